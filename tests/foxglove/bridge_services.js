// The Foxglove bridge's service oscar/config, checked with Foxglove's own client
// (@foxglove/ws-protocol): a bridge started without --allow-config advertises no service and
// refuses a call; one started with it advertises oscar/config, answers malformed calls with a
// failure and an error status (and goes on), and a valid call changes a module's configuration,
// seen in the module's own published state (oscar/registry/module_state, decoded from its OMG
// IDL) and in its behaviour (its robot state's rate). Called by bridge_client.js.
"use strict";

const ROBOT = "oscar/cue/r7/state", MODULE_STATE = "oscar/registry/module_state";
const encode = (o) => new Uint8Array(Buffer.from(typeof o === "string" ? o : JSON.stringify(o)));

// Calls a service; resolves with { response } or { failure } (or { timeout }).
function call(client, serviceId, callId, payload, encoding = "json", ms = 8000) {
  return new Promise((resolve) => {
    const timer = setTimeout(() => { cleanup(); resolve({ timeout: true }); }, ms);
    const onResponse = (r) => { if (r.callId === callId) { cleanup(); resolve({ response: r }); } };
    const onFailure = (f) => { if (f.callId === callId) { cleanup(); resolve({ failure: f }); } };
    function cleanup() {
      clearTimeout(timer);
      client.client.off("serviceCallResponse", onResponse);
      client.client.off("serviceCallFailure", onFailure);
    }
    client.client.on("serviceCallResponse", onResponse);
    client.client.on("serviceCallFailure", onFailure);
    client.client.sendServiceCallRequest({ serviceId, callId, encoding, data: encode(payload) });
  });
}

// The first error status `client` got after its first `n` (the failure comes first: statuses
// follow the protocol's replies), once it arrived.
async function errorStatusSince(client, n, until) {
  const find = () => client.statuses.slice(n).find((s) => s.level === 2);
  await until(() => find() !== undefined, 3000);
  return find();
}

// The robot kernel r7's cycle as its module published it last (ms), from oscar::ModuleState.
function publishedCycleMs(states) {
  for (let i = states.length - 1; i >= 0; --i) {
    const k = (states[i].msg.kernels || []).find((x) => x.name === "r7");
    if (states[i].msg.module_name === "robot" && k) return Number(k.cycle_ns) / 1e6;
  }
  return undefined;
}

async function checkServices(a, configUrl, { check, until, sleep, Client, figures, rateHz }) {
  // Without --allow-config: nothing advertised, a call refused.
  let advertised = false;
  a.client.on("advertiseServices", () => { advertised = true; });
  check(!a.serverInfo.capabilities.includes("services") && !advertised,
        `without --allow-config, no services capability (${JSON.stringify(a.serverInfo.capabilities)}) and no service advertised`);
  const before = a.statuses.length;
  const refused = await call(a, 1, 1, { module: "robot", command: "set-cycle", args: ["r7", "50ms"] });
  const status = await errorStatusSince(a, before, until);
  check(refused.failure && /--allow-config/.test(refused.failure.message) && status && /--allow-config/.test(status.message),
        `a call is refused with an error status: ${status ? status.message : JSON.stringify(refused)}`);

  // With --allow-config: oscar/config, JSON with JSON schemas.
  const c = new Client("config", configUrl);
  await until(() => c.services.size > 0, 10000);
  const service = c.services.get("oscar/config");
  check(c.serverInfo && c.serverInfo.capabilities.includes("services") && (c.serverInfo.supportedEncodings || []).includes("json"),
        `with --allow-config: capability services, encoding json (${JSON.stringify(c.serverInfo && c.serverInfo.capabilities)})`);
  if (!check(service && service.request && service.request.encoding === "json" && service.request.schemaEncoding === "jsonschema" &&
             JSON.parse(service.request.schema).title === "oscar.ConfigRequest",
             "oscar/config is advertised with its request's JSON schema")) return;
  await until(() => c.channels.has(ROBOT) && c.channels.has(MODULE_STATE), 10000);
  const robotSub = c.subscribe(ROBOT), stateSub = c.subscribe(MODULE_STATE);
  await sleep(2500);
  const t0 = Date.now();
  const robotBefore = rateHz(c.received.get(robotSub), t0 - 2000, t0);
  const cycleBefore = publishedCycleMs(c.received.get(stateSub));

  // Malformed calls: a failure and an error status each; the bridge goes on.
  const malformed = [
    ["not JSON", service.id, "not json", "json", /must be a JSON object/],
    ["an encoding not offered", service.id, { module: "robot", command: "suspend" }, "cdr", /encoding 'cdr' is not offered/],
    ["a service not advertised", 99, { module: "robot", command: "suspend" }, "json", /no service 99 is advertised/],
    ["shutdown", service.id, { module: "robot", command: "shutdown" }, "json", /command 'shutdown' is not offered/],
    ["a command not offered", service.id, { module: "robot", command: "format-disk" }, "json", /is not offered/],
    ["arguments that are no strings", service.id, { module: "robot", command: "set-cycle", args: ["r7", 50] }, "json", /must be a string/],
    ["a module that does not run", service.id, { module: "nobody", command: "suspend" }, "json", /nobody/],
    ["a kernel the module lacks", service.id, { module: "robot", command: "set-cycle", args: ["r99", "50ms"] }, "json", /r99/],
  ];
  let callId = 10;
  for (const [what, id, payload, encoding, expected] of malformed) {
    const n = c.statuses.length;
    const r = await call(c, id, ++callId, payload, encoding);
    const s = await errorStatusSince(c, n, until);
    check(r.failure && expected.test(r.failure.message) && s,
          `${what}: a call failure and an error status: ${r.failure ? r.failure.message : JSON.stringify(r)}`);
  }
  const n = c.statuses.length;
  c.ws.send(new Uint8Array([2, 1, 0, 0, 0]));  // a truncated service call request
  const truncated = await errorStatusSince(c, n, until);
  check(truncated && /shorter than its 13-byte header/.test(truncated.message),
        `a truncated call frame: an error status: ${truncated ? truncated.message : "none"}`);

  // A burst of garbage calls: each is refused, the bridge goes on.
  let burstFailures = 0;
  const countBurst = (f) => { if (f.callId >= 1000) ++burstFailures; };
  c.client.on("serviceCallFailure", countBurst);
  for (let i = 0; i < 200; ++i) {
    c.client.sendServiceCallRequest({ serviceId: service.id, callId: 1000 + i, encoding: "json", data: encode("{\"module\": 7}") });
  }
  await until(() => burstFailures === 200, 5000);
  c.client.off("serviceCallFailure", countBurst);
  check(burstFailures === 200, `a burst of 200 malformed calls: ${burstFailures} failures answered`);

  // A valid call changes the module's configuration.
  const ok = await call(c, service.id, ++callId, { module: "robot", command: "set-cycle", args: ["r7", "50ms"] });
  let answer = {};
  try { answer = JSON.parse(Buffer.from(ok.response.data).toString("utf8")); } catch (e) { answer = { error: String(e) }; }
  const r7 = (answer.kernels || []).find((k) => k.name === "r7") || {};
  check(ok.response && ok.response.encoding === "json" && r7.cycle_ms === 50,
        `set-cycle r7 50ms is answered with the module's new state: r7 ${r7.mode} ${r7.cycle_ms} ms (${answer.transition || JSON.stringify(ok)})`);
  const t1 = Date.now();
  await sleep(3500);
  const robotAfter = rateHz(c.received.get(robotSub), t1 + 1000, Date.now());
  const cycleAfter = publishedCycleMs(c.received.get(stateSub));
  figures.robot_hz = { before: robotBefore, after: robotAfter };
  check(cycleBefore === 100 && cycleAfter === 50,
        `the module publishes its new cycle: r7 ${cycleBefore} ms before, ${cycleAfter} ms after`);
  check(robotAfter > 1.6 * robotBefore,
        `and behaves so: r7's states ${robotBefore.toFixed(1)} Hz before, ${robotAfter.toFixed(1)} Hz after`);
  c.close();
}

module.exports = { checkServices };
