// The Foxglove bridge's side channels, checked with Foxglove's own client and published schemas
// (@foxglove/schemas): images (also plain ones) as foxglove.RawImage and foxglove.CompressedImage (JPEG), robot states as foxglove.SceneUpdate, the
// system graph as JSON — each decoded the way Foxglove decodes a `json` channel, from the
// advertised JSON schema alone (JSON.parse, then every field the schema marks
// contentEncoding "base64" to bytes). The bridge's schemas for Foxglove's types are its own;
// they and the messages must follow the published ones (schema_checks.js). Called by
// bridge_client.js with its helpers.
"use strict";
const published = require("@foxglove/schemas/jsonschema");
const { mismatch, undeclared, publishedDrift, foxgloveParserRefuses } = require("./schema_checks");

const CAM = "oscar/cue/cam/out", CAM_SIDE = "foxglove/cam/out", CAM_JPEG = "foxglove/cam/out/compressed";
const ROBOT_SIDE = "foxglove/r7/state", GRAPH = "foxglove/system/graph";
const PLAIN = "oscar/cue/pcam/out", PLAIN_SIDE = "foxglove/pcam/out";

// A `json` channel's message as Foxglove reads it, using only its schema.
function decodeJson(schema, value) {
  if (schema.contentEncoding === "base64" && typeof value === "string") {
    return new Uint8Array(Buffer.from(value, "base64"));
  }
  if (schema.type === "object" && value && typeof value === "object" && schema.properties) {
    for (const [k, sub] of Object.entries(schema.properties)) if (k in value) value[k] = decodeJson(sub, value[k]);
  }
  if (schema.type === "array" && Array.isArray(value) && schema.items) return value.map((v) => decodeJson(schema.items, v));
  return value;
}

// Subscribes `client` to a json channel; its messages arrive checked and decoded.
function subscribeJson(client, topic) {
  const c = client.channels.get(topic);
  const schema = JSON.parse(c.schema);
  // A message in one of Foxglove's types also sends nothing its schema leaves out, and conforms
  // to the published schema.
  const theirs = c.schemaName.startsWith("foxglove.") ? published[c.schemaName.slice("foxglove.".length)] : undefined;
  client.readers.set(c.id, {
    readMessage: (bytes) => {
      const raw = JSON.parse(Buffer.from(bytes).toString("utf8"));
      let bad = mismatch(schema, raw);
      if (!bad && theirs) {
        const extra = undeclared(schema, raw);
        bad = extra ? `${extra} is not declared` : mismatch(theirs, raw) && `published: ${mismatch(theirs, raw)}`;
      }
      return bad ? { error: `does not conform to ${c.schemaName}: ${bad}` } : decodeJson(schema, raw);
    },
  });
  const id = client.client.subscribe(c.id);
  const list = [];
  list.channel = c.id;
  client.received.set(id, list);
  return id;
}

// What a JPEG file's bytes say of themselves: SOI first, EOI last, and the size and components
// of its first start-of-frame header (SOF0..SOF2), found by walking the marker segments.
function jpegFrame(bytes) {
  const out = { soi: bytes[0] === 0xff && bytes[1] === 0xd8,
                eoi: bytes[bytes.length - 2] === 0xff && bytes[bytes.length - 1] === 0xd9 };
  for (let i = 2; i + 9 < bytes.length && bytes[i] === 0xff;) {
    const marker = bytes[i + 1], length = (bytes[i + 2] << 8) | bytes[i + 3];
    if (marker >= 0xc0 && marker <= 0xc2) {
      return { ...out, height: (bytes[i + 5] << 8) | bytes[i + 6], width: (bytes[i + 7] << 8) | bytes[i + 8],
               components: bytes[i + 9] };
    }
    i += 2 + length;
  }
  return out;
}

// foxglove/cam/out/compressed: the camera's images as foxglove.CompressedImage, a JPEG each of
// the source's size, decoded with the advertised schema alone; converted only while subscribed.
async function checkCompressedImages(a, { check, until, sleep, figures, lastGraph }) {
  const c = a.channels.get(CAM_JPEG);
  if (!check(c, `${CAM_JPEG} is advertised beside its source`)) return;
  const drift = publishedDrift(JSON.parse(c.schema), published.CompressedImage);
  const refused = foxgloveParserRefuses(JSON.parse(c.schema));
  check(c.encoding === "json" && c.schemaEncoding === "jsonschema" && c.schemaName === "foxglove.CompressedImage" &&
        drift.length === 0 && refused.length === 0,
        `${CAM_JPEG}: json, a jsonschema foxglove.CompressedImage that follows the published one and Foxglove's parser takes (${c.encoding}, ${c.schemaEncoding}, ${c.schemaName}) ${drift.concat(refused).join("; ")}`);
  check(sideCounter(lastGraph(), CAM_JPEG) === 0, `before anyone subscribes, no JPEG is made (${sideCounter(lastGraph(), CAM_JPEG)})`);
  const sub = subscribeJson(a, CAM_JPEG);
  await until(() => a.received.get(sub).length >= 20, 10000);
  a.client.unsubscribe(sub);
  const jpegs = a.received.get(sub);
  const bad = jpegs.find((m) => {
    if (!m.msg || m.msg.error || m.msg.format !== "jpeg" || m.msg.frame_id !== "cam" || !(m.msg.data instanceof Uint8Array)) return true;
    const f = jpegFrame(m.msg.data);
    return !(f.soi && f.eoi && f.width === 640 && f.height === 480 && f.components === 1);
  });
  check(jpegs.length >= 20, `${jpegs.length} CompressedImages (20 Hz source)`);
  check(jpegs.length > 0 && !bad,
        "every CompressedImage decodes with only its schema: format jpeg, frame cam, a JPEG from SOI to EOI whose " +
        "frame header says 640 x 480, one component (the source image's size)" +
        (bad ? ` (first bad: ${JSON.stringify(bad.msg && { ...bad.msg, data: bad.msg.data && jpegFrame(bad.msg.data) }).slice(0, 200)})` : ""));
  const sizes = jpegs.map((m) => (m.msg.data || []).length).sort((x, y) => x - y);
  figures.side_jpegs = { received: jpegs.length, median_bytes: sizes[Math.floor(sizes.length / 2)] };
  await sleep(1500);
  const converted = sideCounter(lastGraph(), CAM_JPEG);
  await sleep(1500);
  check(converted >= jpegs.length && sideCounter(lastGraph(), CAM_JPEG) === converted,
        `once unsubscribed, JPEG conversion stops: ${converted} made for the ${jpegs.length} received, ${sideCounter(lastGraph(), CAM_JPEG)} later`);
}

// A plain image (the zero-copy form, 768 x 576 bytes of which byte_count are the image): raw,
// decoded with Foxglove's OMG IDL reader from the advertised schema alone; as a RawImage, its
// first byte_count pixels.
async function checkPlainImages(a, { check, until, imageComplete }) {
  const raw = a.channels.get(PLAIN), side = a.channels.get(PLAIN_SIDE);
  if (!check(raw && raw.schemaName === "oscar::PlainGvImage" && side && side.schemaName === "foxglove.RawImage",
             `${PLAIN} (oscar::PlainGvImage) and ${PLAIN_SIDE} (foxglove.RawImage) are advertised`)) return;
  const rawSub = a.subscribe(PLAIN), sideSub = subscribeJson(a, PLAIN_SIDE);
  await until(() => a.received.get(rawSub).length >= 3 && a.received.get(sideSub).length >= 3, 10000);
  a.client.unsubscribe(rawSub);
  a.client.unsubscribe(sideSub);
  const raws = a.received.get(rawSub), sides = a.received.get(sideSub);
  const rawRight = (m) => m.msg && !m.msg.error && m.msg.dx === 320 && m.msg.dy === 240 &&
    m.msg.byte_count === 320 * 240 && m.msg.image.length === 768 * 576 && m.msg.header.seq > 0n &&
    imageComplete({ msg: { dx: 320, dy: 240, image: m.msg.image.subarray(0, m.msg.byte_count) } });
  check(raws.length >= 3 && raws.every(rawRight),
        `${raws.length} plain images decode raw with only their schema: 320 x 240, byte_count ${320 * 240} of a ` +
        `${768 * 576}-byte array, the pixel pattern intact`);
  const sideRight = (m) => m.msg && !m.msg.error && m.msg.width === 320 && m.msg.height === 240 &&
    m.msg.encoding === "mono8" && m.msg.frame_id === "pcam" && m.msg.data instanceof Uint8Array &&
    imageComplete({ msg: { dx: 320, dy: 240, image: m.msg.data } });
  check(sides.length >= 3 && sides.every(sideRight),
        `${sides.length} plain images as RawImages: 320 x 240 mono8, frame pcam, all ${320 * 240} pixels intact` +
        (sides.find((m) => !sideRight(m)) ? ` (first bad: ${JSON.stringify(sides.find((m) => !sideRight(m)).msg).slice(0, 200)})` : ""));
}

function sideCounter(graph, topic) {
  const s = ((graph && graph.side_channels) || []).find((x) => x.topic === topic);
  return s ? s.converted : undefined;
}

async function checkSideChannels(a, { check, until, sleep, figures, imageComplete, expectJpeg }) {
  await until(() => a.channels.has(CAM_SIDE) && a.channels.has(ROBOT_SIDE) && a.channels.has(GRAPH), 10000);
  for (const [topic, name] of [[CAM_SIDE, "RawImage"], [ROBOT_SIDE, "SceneUpdate"]]) {
    const c = a.channels.get(topic);
    if (!check(c, `${topic} is advertised beside its source`)) return;
    const drift = publishedDrift(JSON.parse(c.schema), published[name]);
    const refused = foxgloveParserRefuses(JSON.parse(c.schema));
    check(c.encoding === "json" && c.schemaEncoding === "jsonschema" && c.schemaName === `foxglove.${name}` &&
          drift.length === 0 && refused.length === 0,
          `${topic}: json, a jsonschema foxglove.${name} that follows the published one and Foxglove's parser takes (${c.encoding}, ${c.schemaEncoding}, ${c.schemaName}) ${drift.concat(refused).join("; ")}`);
  }
  const g = a.channels.get(GRAPH);
  if (!check(g && g.encoding === "json" && g.schemaEncoding === "jsonschema" && g.schemaName === "oscar.SystemGraph",
             `${GRAPH} is advertised: json, jsonschema oscar.SystemGraph`)) return;
  const graphRefused = foxgloveParserRefuses(JSON.parse(g.schema));
  check(graphRefused.length === 0, `Foxglove's parser takes the schema oscar.SystemGraph ${graphRefused.join("; ")}`);

  // The graph: every booted module with its state, kernels and wiring.
  const graphSub = subscribeJson(a, GRAPH);
  const graphs = a.received.get(graphSub);
  await until(() => graphs.length > 0, 5000);
  const graph = (graphs[graphs.length - 1] || {}).msg || {};
  check(!graph.error, `the graph conforms to its schema ${graph.error || ""}`);
  const modules = (graph.modules || []).map((m) => `${m.name}:${m.status}`).sort().join(" ");
  check(graph.system === "viewed" && graph.state === "running" &&
        modules === "arm:running camera:running plain_camera:running robot:running sources:running",
        `the graph lists the booted modules with their states: ${graph.system} ${graph.state}, ${modules}`);
  const sig = (graph.modules || []).flatMap((m) => m.kernels).find((k) => k.name === "sig") || {};
  check(sig.type === "bench_source" && sig.mode === "continuous" && sig.cycle_ms === 20,
        `kernel sig: ${sig.type} ${sig.mode} ${sig.cycle_ms} ms`);
  const camChannel = (graph.channels || []).find((c) => c.source === "cam/out") || {};
  check(camChannel.type === "oscar::GvImage" && camChannel.producer === "cam",
        `channel cam/out: ${camChannel.type} from ${camChannel.producer}`);

  // Reading the image topic raw converts nothing (the client read it raw for 3 s already).
  const camSub = a.subscribe(CAM);
  await sleep(1500);
  const lastGraph = () => (graphs[graphs.length - 1] || {}).msg;
  const idle = sideCounter(lastGraph(), CAM_SIDE);
  check(idle === 0 && a.received.get(camSub).length > 0,
        `while nobody subscribes to ${CAM_SIDE}, no image is converted (${idle}), though ${CAM} is read raw (${a.received.get(camSub).length} images)`);

  // Subscribed, images arrive as foxglove.RawImage, decoded with the schema alone.
  const sideSub = subscribeJson(a, CAM_SIDE);
  await sleep(2000);
  a.client.unsubscribe(sideSub);
  const images = a.received.get(sideSub);
  const decodedRight = (m) => m.msg && !m.msg.error && m.msg.width === 640 && m.msg.height === 480 &&
    m.msg.encoding === "mono8" && m.msg.step === 640 && m.msg.frame_id === "cam" &&
    m.msg.data instanceof Uint8Array && imageComplete({ msg: { dx: 640, dy: 480, image: m.msg.data } });
  check(images.length >= 20, `${images.length} RawImages in 2 s (20 Hz source)`);
  check(images.every(decodedRight),
        `every RawImage decodes with only its schema: 640 x 480 mono8, step 640, frame cam, all ${640 * 480} pixels intact` +
        (images.find((m) => !decodedRight(m)) ? ` (first bad: ${JSON.stringify(images.find((m) => !decodedRight(m)).msg).slice(0, 200)})` : ""));
  const nowS = Date.now() / 1000;
  check(images.every((m) => Math.abs(m.msg.timestamp.sec + m.msg.timestamp.nsec / 1e9 - nowS) < 60),
        "their timestamps are the cues' stamps (recent)");
  await sleep(1500);  // in flight, then a graph after the unsubscription
  const stopped = sideCounter(lastGraph(), CAM_SIDE);
  await sleep(2000);
  const later = sideCounter(lastGraph(), CAM_SIDE);
  figures.side_images = { received: images.length, converted: stopped };
  check(stopped >= images.length && later === stopped && a.received.get(camSub).length > 0,
        `once unsubscribed, conversion stops: ${stopped} converted for the ${images.length} received, ${later} two seconds later, the raw topic still read`);
  a.client.unsubscribe(camSub);
  await checkPlainImages(a, { check, until, imageComplete });
  if (expectJpeg) {
    await checkCompressedImages(a, { check, until, sleep, figures, lastGraph });
  } else {
    check(!a.channels.has(CAM_JPEG), `a bridge built without libjpeg advertises no ${CAM_JPEG}`);
  }

  // A robot state as a SceneUpdate: the robot as an entity where it stands.
  const sceneSub = subscribeJson(a, ROBOT_SIDE);
  await until(() => a.received.get(sceneSub).length >= 3, 5000);
  a.client.unsubscribe(sceneSub);
  const scene = (a.received.get(sceneSub)[0] || {}).msg || {};
  const e = ((scene.entities || [])[0]) || {};
  const disc = (e.cylinders || [])[0] || { pose: { position: {} }, size: {} };
  check(!scene.error && e.id === "r7" && e.frame_id === "world" &&
        Math.abs(disc.pose.position.x - 3) < 1e-6 && Math.abs(disc.pose.position.y - 4) < 1e-6 &&
        Math.abs(disc.size.x - 0.6) < 1e-9,
        `r7's state is a SceneUpdate: entity ${e.id} in ${e.frame_id}, a disc at (${disc.pose.position.x}, ${disc.pose.position.y}) of diameter ${disc.size.x} ${scene.error || ""}`);
  a.client.unsubscribe(graphSub);
}

module.exports = { checkSideChannels, subscribeJson };
