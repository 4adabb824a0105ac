// The bridge's JSON schemas for Foxglove's message types (tools/bridge/schemas/foxglove.*.json)
// are OSCAR's own: they declare only the fields the bridge sends. These checks hold them to
// Foxglove's published schemas (@foxglove/schemas), so a field whose name or type drifts from
// Foxglove's fails the test, and hold the bridge's messages to both schemas.
//
//   node schema_checks.js --schemas SCHEMAS.json --messages MESSAGES.json
//
// SCHEMAS.json maps a schema name (foxglove.RawImage) to the schema the bridge advertises,
// MESSAGES.json maps it to a list of messages its encoders made. Prints each check and exits 1
// if one failed. bridge_views.js uses the same functions on what a running bridge sends.
"use strict";

// What of `value` does not conform to `schema`: "" if all does. As far as the bridge's schemas
// and Foxglove's use JSON schema: type, required, properties, items, maxItems, const alternatives.
function mismatch(schema, value, path = "$") {
  if (schema.oneOf) return schema.oneOf.some((a) => a.const === value) ? "" : `${path}: no alternative`;
  const t = schema.type;
  const ok = !t || (t === "object" && value && typeof value === "object" && !Array.isArray(value)) ||
    (t === "array" && Array.isArray(value)) || (t === "string" && typeof value === "string") ||
    (t === "integer" && Number.isInteger(value)) || (t === "number" && typeof value === "number") ||
    (t === "boolean" && typeof value === "boolean");
  if (!ok) return `${path}: expected ${t}, got ${JSON.stringify(value).slice(0, 60)}`;
  if (t === "object") {
    for (const r of schema.required || []) if (!(r in value)) return `${path}: lacks ${r}`;
    for (const [k, sub] of Object.entries(schema.properties || {})) {
      if (k in value) { const m = mismatch(sub, value[k], `${path}.${k}`); if (m) return m; }
    }
  }
  if (t === "array") {
    if (schema.maxItems !== undefined && value.length > schema.maxItems) return `${path}: more than ${schema.maxItems} items`;
    if (schema.items) {
      for (let i = 0; i < value.length; ++i) { const m = mismatch(schema.items, value[i], `${path}[${i}]`); if (m) return m; }
    }
  }
  return "";
}

// The first field of `value` that `schema` does not declare (a property it does not list, an
// item of an array whose items it does not describe), as a path; "" if there is none.
function undeclared(schema, value, path = "$") {
  if (Array.isArray(value)) {
    if (value.length > 0 && !schema.items) return `${path}[0]`;
    for (let i = 0; i < value.length; ++i) { const u = undeclared(schema.items, value[i], `${path}[${i}]`); if (u) return u; }
  } else if (value && typeof value === "object") {
    for (const [k, v] of Object.entries(value)) {
      const sub = (schema.properties || {})[k];
      if (!sub) return `${path}.${k}`;
      const u = undeclared(sub, v, `${path}.${k}`);
      if (u) return u;
    }
  }
  return "";
}

// Where `ours` departs from Foxglove's `published` schema, one line each: a property ours
// declares that the published one lacks at that path, a different type or content encoding, a
// property the published one requires of an object ours declares that ours leaves out, another
// title at the top. Empty if ours follows it. A list ours never fills (maxItems 0) declares only
// its items' type, which must be the published one.
function publishedDrift(ours, published, path = "$") {
  const problems = [];
  if (path === "$" && ours.title !== published.title) problems.push(`$: title ${ours.title}, published ${published.title}`);
  if (ours.type !== published.type) problems.push(`${path}: type ${ours.type}, published ${published.type}`);
  if (ours.contentEncoding !== published.contentEncoding) {
    problems.push(`${path}: content encoding ${ours.contentEncoding}, published ${published.contentEncoding}`);
  }
  if (ours.properties) {
    const theirs = published.properties || {};
    for (const [k, sub] of Object.entries(ours.properties)) {
      if (!(k in theirs)) problems.push(`${path}.${k}: not in the published schema`);
      else problems.push(...publishedDrift(sub, theirs[k], `${path}.${k}`));
    }
    for (const r of published.required || []) {
      if (!(r in ours.properties)) problems.push(`${path}.${r}: required by the published schema, not declared`);
    }
  }
  if (ours.items) {
    if (!published.items) problems.push(`${path}[]: items, none in the published schema`);
    else if (ours.maxItems === 0) {
      // always empty: its items declare their type (Foxglove's parser needs it), no fields
      if (ours.items.type !== published.items.type) {
        problems.push(`${path}[]: type ${ours.items.type}, published ${published.items.type}`);
      }
      if (Object.keys(ours.items.properties || {}).length > 0) {
        problems.push(`${path}[]: declares fields of items it never sends (maxItems 0)`);
      }
    } else problems.push(...publishedDrift(ours.items, published.items, `${path}[]`));
  }
  return problems;
}

// What Foxglove's parser of a channel's JSON schema (its jsonschema message definitions) cannot
// take, one line each: it reads only objects with "properties" whose fields are booleans,
// strings, numbers, objects, lists of those (each list naming its item type) or number
// alternatives (oneOf of consts), and refuses the whole channel ("Failed to parse channel schema")
// otherwise. Empty if it can parse `schema`.
function foxgloveParserRefuses(schema, path = "$") {
  if (schema.type !== "object") return [`${path}: type ${schema.type}, not object`];
  if (!schema.properties) return [`${path}: an object without properties`];
  const problems = [];
  for (const [k, sub] of Object.entries(schema.properties)) {
    const at = `${path}.${k}`;
    if (Array.isArray(sub.oneOf)) {
      if (!sub.oneOf.every((a) => typeof a.const === "number")) problems.push(`${at}: oneOf of other than numbers`);
    } else if (sub.type === "object") {
      problems.push(...foxgloveParserRefuses(sub, at));
    } else if (sub.type === "array") {
      const t = sub.items && sub.items.type;
      if (t === "object") problems.push(...foxgloveParserRefuses(sub.items, `${at}[]`));
      else if (!["boolean", "string", "number", "integer"].includes(t)) problems.push(`${at}[]: item type ${t}`);
    } else if (sub.type === "string") {
      if (![undefined, "base64"].includes(sub.contentEncoding)) problems.push(`${at}: content encoding ${sub.contentEncoding}`);
    } else if (!["boolean", "number", "integer"].includes(sub.type)) {
      problems.push(`${at}: type ${sub.type}`);
    }
  }
  return problems;
}

module.exports = { mismatch, undeclared, publishedDrift, foxgloveParserRefuses };

if (require.main === module) {
  const fs = require("fs");
  const published = require("@foxglove/schemas/jsonschema");
  const arg = (name) => JSON.parse(fs.readFileSync(process.argv[process.argv.indexOf(name) + 1], "utf8"));
  const schemas = arg("--schemas"), messages = arg("--messages");
  let failed = 0;
  const check = (ok, what) => {
    console.log(`${ok ? "ok  " : "FAIL"} ${what}`);
    if (!ok) ++failed;
    return ok;
  };
  // The check itself must see drift: a renamed field and a changed type.
  const rename = (o) => { const [k, v] = Object.entries(o.properties)[0]; delete o.properties[k]; o.properties[`${k}_`] = v; };
  for (const [name, ours] of Object.entries(schemas)) {
    const theirs = published[name.replace(/^foxglove\./, "")];
    if (!check(theirs !== undefined, `${name} is a schema @foxglove/schemas publishes`)) continue;
    const drift = publishedDrift(ours, theirs);
    check(drift.length === 0, `${name} declares only fields of the published schema, with their types` +
          (drift.length ? `:\n       ${drift.join("\n       ")}` : ""));
    const renamed = structuredClone(ours), retyped = structuredClone(ours);
    rename(renamed);
    const first = Object.keys(retyped.properties)[0];
    retyped.properties[first].type = retyped.properties[first].type === "string" ? "integer" : "string";
    check(publishedDrift(renamed, theirs).length > 0 && publishedDrift(retyped, theirs).length > 0,
          `${name}: a renamed field or a changed type would be found`);
    const refused = foxgloveParserRefuses(ours);
    check(refused.length === 0, `${name}: Foxglove's parser of JSON schemas takes it` +
          (refused.length ? `:\n       ${refused.join("\n       ")}` : ""));
    const itemless = structuredClone(ours);
    itemless.properties.a_list_ = { type: "array", maxItems: 0 };
    check(foxgloveParserRefuses(itemless).length > 0, `${name}: a list without its item type would be found`);
    const list = messages[name] || [];
    check(list.length > 0, `${name}: ${list.length} messages from the bridge's encoders`);
    list.forEach((m, i) => {
      const extra = undeclared(ours, m);
      const bad = mismatch(ours, m) || (extra && `${extra} is not declared`);
      check(!bad, `${name} message ${i} conforms to the bridge's schema and sends only what it declares ${bad}`);
      const badPublished = mismatch(theirs, m);
      check(!badPublished, `${name} message ${i} conforms to the published schema ${badPublished}`);
    });
  }
  process.exit(failed ? 1 : 0);
}
