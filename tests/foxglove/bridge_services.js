// The Foxglove bridge's service oscar/config, checked with Foxglove's own client
// (@foxglove/ws-protocol): a bridge started without --allow-config advertises no service and
// refuses a call; one started with it advertises oscar/config, answers malformed calls with a
// failure and an error status (and goes on), and a valid call changes a module's configuration,
// seen in the module's own published state (oscar/registry/module_state, decoded from its OMG
// IDL) and in its behaviour (its robot state's rate). Called by bridge_client.js.
"use strict";
const { checkOwnTypes, HOLD } = require("./bridge_own_types");

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
  await checkCommandServices(c, { check, until, robotSub, callId: 2000, figures });
  await checkOwnTypes(a, c, { check, until, call, callId: 3000 });
  c.close();
}

const parse = (r) => { try { return JSON.parse(Buffer.from(r.response.data).toString("utf8")); } catch (e) { return { error: String(e) }; } };
const said = (r) => (r.failure ? r.failure.message : r.response ? Buffer.from(r.response.data).toString("utf8") : JSON.stringify(r));

// Kernel command ports as services: robot r7 (robot_sim) declares propose, commit, abort and
// committed, the arm (a type of its own, bridge_own_types.js) hold; the other kernels declare none. A proposal and its commit, sent from
// Foxglove's client, make r7 drive half a metre (seen in its published state); wrong arguments
// and a commit the kernel refuses fail with the reason.
async function checkCommandServices(c, { check, until, robotSub, callId, figures }) {
  const R7 = ["abort", "commit", "committed", "propose"].map((n) => `oscar/robot/r7/${n}`);
  await until(() => R7.every((n) => c.services.has(n)) && c.services.has(HOLD), 10000);
  const offered = [...c.services.keys()].filter((n) => n !== "oscar/config").sort();
  check(JSON.stringify(offered) === JSON.stringify([HOLD, ...R7]),
        `the command ports of r7 and the arm are services, no other kernel declares any: ${offered.join(", ")}`);
  const propose = c.services.get(R7[3]), commit = c.services.get(R7[1]);
  if (!propose || !commit) return;
  const schema = JSON.parse(propose.request.schema);
  const waypoint = (((schema.properties || {}).sections || {}).items || {}).properties;
  check(propose.type === "oscar::Trajectory" && propose.request.encoding === "json" &&
        propose.request.schemaEncoding === "jsonschema" && schema.title === "oscar::Trajectory" &&
        waypoint && waypoint.waypoints.items.properties.t_ns.pattern === "^-?[0-9]+$" &&
        JSON.parse(commit.response.schema).title === "oscar.CommandResponse",
        `propose is advertised with a JSON schema of oscar::Trajectory's members, commit answers oscar.CommandResponse`);

  // Errors, each a call failure with the reason and an error status.
  const wrong = [
    ["a value of the wrong type", commit, { robot: "r7", transaction: "seven" }, /oscar\/robot\/r7\/commit: wrong arguments: transaction: 'seven' is no unsigned long long/],
    ["a member the request type lacks", commit, { robot: "r7", tx: 7 }, /wrong arguments: oscar::TransactionDecision has no member 'tx'/],
    ["a commit the kernel refuses", commit, { robot: "r7", transaction: 9 }, /robot command r7 commit: .*refused by kernel 'r7': no proposal of transaction 9 is pending/],
  ];
  for (const [what, service, payload, expected] of wrong) {
    const n = c.statuses.length;
    const r = await call(c, service.id, ++callId, payload);
    const s = await errorStatusSince(c, n, until);
    check(r.failure && expected.test(r.failure.message) && s, `${what}: ${said(r)}`);
  }

  // From 1.5 s on, half a metre along x in 1 s, then stand there.
  const states = c.received.get(robotSub);
  const last = states[states.length - 1].msg;
  const x0 = last.x, y0 = last.y;
  const from = BigInt(Date.now()) * 1000000n + 1500000000n, to = from + 1000000000n;
  const proposal = {
    robot: "r7", transaction: "7",
    sections: [{ from_ns: from.toString(), open_end: true,
                 waypoints: [{ x: x0, y: y0, t_ns: from.toString() }, { x: x0 + 0.5, y: y0, t_ns: to.toString() }] }],
  };
  const proposed = await call(c, propose.id, ++callId, proposal);
  const ack = proposed.response ? parse(proposed) : {};
  check(proposed.response && ack.module === "robot" && ack.kernel === "r7" && ack.command === "propose" &&
        /^transaction 7 pending: 1 section\(s\)/.test(ack.answer), `propose is acknowledged: ${said(proposed)}`);
  const committed = await call(c, commit.id, ++callId, { robot: "r7", transaction: 7 });
  check(committed.response && /^transaction 7 committed/.test(parse(committed).answer), `commit is accepted: ${said(committed)}`);
  const sent = states.length;
  const arrived = () => {
    const m = states[states.length - 1].msg;
    return Math.abs(m.x - (x0 + 0.5)) < 1e-3 && Math.abs(m.y - y0) < 1e-3;
  };
  await until(arrived, 8000);
  const end = states[states.length - 1].msg;
  // While it drives, its state names the transaction (standing at the end, none).
  const driving = states.slice(sent).filter((m) => Number(m.msg.transaction) === 7 && m.msg.speed > 0);
  figures.r7_driven = { from: [x0, y0], to: [end.x, end.y], states_in_transaction_7: driving.length };
  check(arrived() && driving.length > 0,
        `and r7 drives there: from (${x0}, ${y0}) to (${end.x}, ${end.y}), ${driving.length} states moving in transaction 7`);
}

module.exports = { checkServices };
