// A module of types OSCAR does not define (tests/own_types: acme::ArmState published by arm/state,
// acme::HoldRequest taken by its command port hold), seen through the bridge: it announces their
// IDL texts, so the bridge serves its topic with the module's own `omgidl` schema, which
// Foxglove's reader decodes alone, and offers its command port as a service. Called by
// bridge_services.js with the client `a` (no --allow-config) and `c` (with it).
"use strict";

const ARM = "oscar/cue/arm/state", HOLD = "oscar/arm/arm/hold";
const GRIP_OPEN = 0, GRIP_CLOSED = 1;  // acme::Grip's enumerators, as Foxglove's reader gives them
// A decoded message as text (its 64-bit integers are BigInts, which JSON.stringify refuses).
const shown = (msg) => JSON.stringify(msg, (k, v) => (typeof v === "bigint" ? v.toString() : v));

async function checkOwnTypes(a, c, { check, until, call, callId }) {
  await until(() => a.channels.has(ARM), 10000);
  const arm = a.channels.get(ARM);
  if (!check(arm && arm.encoding === "cdr" && arm.schemaEncoding === "omgidl" && arm.schemaName === "acme::ArmState" &&
             /module acme/.test(arm.schema) && /struct CueHeader/.test(arm.schema),
             `${ARM} is advertised with the IDL its module announced: ${arm ? arm.schemaName : "not advertised"}`)) return;
  const sub = a.subscribe(ARM);
  const states = a.received.get(sub);
  await until(() => states.length >= 5, 5000);
  check(states.length >= 5 && states.every((m) => !m.msg.error && m.msg.tool === "welder" && m.msg.joints_rad.length === 3 &&
                                                 m.msg.grip === GRIP_OPEN && m.msg.header.source === "arm/state"),
        `its messages decode with that schema alone (${states.length}): ${shown((states[0] || {}).msg)}`);

  await until(() => c.services.has(HOLD), 10000);
  const hold = c.services.get(HOLD);
  const schema = hold ? JSON.parse(hold.request.schema) : {};
  const props = schema.properties || {};
  if (!check(hold && hold.type === "acme::HoldRequest" && props.seconds && props.seconds.type === "number" &&
             JSON.stringify((props.grip || {}).enum) === JSON.stringify(["GRIP_OPEN", "GRIP_CLOSED"]),
             `${HOLD} is a service with a JSON schema of acme::HoldRequest: ${JSON.stringify(schema)}`)) return;
  const r = await call(c, hold.id, ++callId, { seconds: 2.5, grip: "GRIP_CLOSED" });
  const answer = r.response ? JSON.parse(Buffer.from(r.response.data).toString("utf8")).answer : undefined;
  check(answer === "holding closed for 2.5 s", `a call is encoded as acme::HoldRequest and accepted: ${answer || JSON.stringify(r)}`);
  const sent = states.length;
  await until(() => states.length > sent + 2 && states[states.length - 1].msg.grip === GRIP_CLOSED, 5000);
  check(states[states.length - 1].msg.grip === GRIP_CLOSED, "and the arm holds closed from then on");
  a.client.unsubscribe(sub);
}

module.exports = { checkOwnTypes, HOLD };
