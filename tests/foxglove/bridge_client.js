// The client side of the Foxglove bridge test, with Foxglove's own libraries only:
// @foxglove/ws-protocol (the client Foxglove connects with), @foxglove/omgidl-parser and
// @foxglove/omgidl-serialization (how Foxglove decodes `omgidl` + `cdr` channels).
//
//   node bridge_client.js --url ws://127.0.0.1:PORT --config-url ws://127.0.0.1:PORT2
//        [--expect-jpeg | --no-jpeg] --late oscar-run ARGS...
//
// The system under test publishes oscar::Bool on oscar/cue/sig/out every 20 ms, oscar::GvImage
// (640 x 480) on oscar/cue/cam/out every 50 ms and robot r7's oscar::RobotState every 100 ms;
// --url is a bridge started without --allow-config, --config-url one started with it; --late is
// the command of a module whose topic oscar/cue/late/out appears only when this script starts
// it; --no-jpeg: the bridge was built without libjpeg (no CompressedImage channel). The side
// channels are checked in bridge_views.js, the services in bridge_services.js.
// Prints what it measured as JSON and exits 1 if a check failed.
"use strict";
const { spawn } = require("child_process");
const WebSocket = require("ws");
const { FoxgloveClient } = require("@foxglove/ws-protocol");
const { parseIDL } = require("@foxglove/omgidl-parser");
const { MessageReader } = require("@foxglove/omgidl-serialization");
const { checkSideChannels } = require("./bridge_views");
const { checkServices } = require("./bridge_services");

const args = {
  url: process.argv[process.argv.indexOf("--url") + 1],
  configUrl: process.argv[process.argv.indexOf("--config-url") + 1],
};
const lateCommand = process.argv.slice(process.argv.indexOf("--late") + 1);
const SIG = "oscar/cue/sig/out", CAM = "oscar/cue/cam/out", LATE = "oscar/cue/late/out";
const STATE = "oscar/system/state";
const SIG_PERIOD_MS = 20;

const failures = [];
const figures = {};
function check(ok, what) {
  console.log(`${ok ? "ok  " : "FAIL"} ${what}`);
  if (!ok) failures.push(what);
  return ok;
}
// Wall-clock ns with sub-ms resolution (Date.now() has ms only).
const nowNs = () => BigInt(Math.round((performance.timeOrigin + performance.now()) * 1e6));
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
async function until(predicate, ms) {
  const end = Date.now() + ms;
  while (Date.now() < end) {
    if (predicate()) return true;
    await sleep(20);
  }
  return predicate();
}

// One client: its channels by topic, decoders made from the advertised schema alone, and
// every message it received by subscription.
class Client {
  constructor(name, url = args.url) {
    this.name = name;
    this.ws = new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
    this.client = new FoxgloveClient({ ws: this.ws });
    this.channels = new Map();  // topic -> channel
    this.unadvertised = new Set();
    this.readers = new Map();  // channel id -> MessageReader
    this.received = new Map();  // subscription id -> [{ at, timestamp, msg, bytes }]
    this.statuses = [];
    this.errors = [];
    this.services = new Map();  // name -> service
    this.client.on("advertiseServices", (services) => { for (const s of services) this.services.set(s.name, s); });
    this.client.on("unadvertiseServices", (ids) => {
      for (const [name, s] of this.services) if (ids.includes(s.id)) this.services.delete(name);
    });
    this.client.on("serverInfo", (info) => { this.serverInfo = info; });
    this.client.on("advertise", (channels) => {
      for (const c of channels) { this.channels.set(c.topic, c); this.unadvertised.delete(c.id); }
    });
    this.client.on("unadvertise", (ids) => {
      for (const id of ids) this.unadvertised.add(id);
      for (const [topic, c] of this.channels) if (ids.includes(c.id)) this.channels.delete(topic);
    });
    this.client.on("status", (s) => this.statuses.push(s));
    this.client.on("error", (e) => this.errors.push(String(e)));
    this.client.on("message", ({ subscriptionId, timestamp, data }) => {
      const list = this.received.get(subscriptionId);
      if (!list) return;
      const bytes = new Uint8Array(data.buffer, data.byteOffset, data.byteLength);
      let msg = null;
      try { msg = this.readers.get(list.channel).readMessage(bytes); } catch (e) { msg = { error: String(e) }; }
      list.push({ at: Date.now(), atNs: nowNs(), timestamp, msg, size: bytes.byteLength });
    });
  }
  subscribe(topic) {
    const c = this.channels.get(topic);
    if (!this.readers.has(c.id)) this.readers.set(c.id, new MessageReader(c.schemaName, parseIDL(c.schema)));
    const id = this.client.subscribe(c.id);
    const list = [];
    list.channel = c.id;
    this.received.set(id, list);
    return id;
  }
  close() { this.client.close(); }
}

const seqs = (list) => list.map((m) => Number(m.msg.header.seq));
const consecutive = (s) => s.every((v, i) => i === 0 || v === s[i - 1] + 1);
const increasing = (s) => s.every((v, i) => i === 0 || v > s[i - 1]);
const rateHz = (list, from, to) => list.filter((m) => m.at >= from && m.at < to).length / ((to - from) / 1000);
// The producer's rate, from the generation stamps and sequence numbers the cues carry.
function producerHz(list) {
  if (list.length < 2) return 0;
  const a = list[0].msg.header, b = list[list.length - 1].msg.header;
  return (Number(b.seq - a.seq) * 1e9) / Number(b.stamps[0] - a.stamps[0]);
}
// Milliseconds from a cue's generation stamp to its arrival here, as p50 and p99 (a figure, not
// a check: timing depends on the machine; `oscar echo` on the same topic is the comparison).
function latencyMs(list) {
  const d = list.map((m) => Number(m.atNs - m.msg.header.stamps[0]) / 1e6).sort((x, y) => x - y);
  const at = (q) => d[Math.min(d.length - 1, Math.floor(q * d.length))];
  return { p50: Number(at(0.5).toFixed(3)), p99: Number(at(0.99).toFixed(3)), n: d.length };
}
const missing = (s) => s.reduce((n, v, i) => n + (i === 0 ? 0 : v - s[i - 1] - 1), 0);
// Messages of `topic` the bridge told this client it dropped, from its status warnings.
function reportedDrops(client, topic) {
  let n = 0;
  for (const s of client.statuses) {
    const m = new RegExp(`(\\d+) of ${topic}\\b`).exec(s.message);
    if (m) n += Number(m[1]);
  }
  return n;
}
function maxGapMs(list) {
  let gap = 0;
  for (let i = 1; i < list.length; ++i) gap = Math.max(gap, list[i].at - list[i - 1].at);
  return gap;
}
function imageComplete(m) {
  const { dx, dy, image } = m.msg;
  if (image.length !== dx * dy) return false;
  for (let y = 0; y < dy; y += 7) for (let x = 0; x < dx; x += 13) if (image[y * dx + x] !== ((x + y) & 0xff)) return false;
  return true;
}

async function main() {
  // 1. Advertisements: every topic with its OMG IDL schema.
  const a = new Client("a");
  await until(() => a.channels.has(SIG) && a.channels.has(CAM) && a.channels.has(STATE), 15000);
  check(a.serverInfo && a.serverInfo.name === "oscar bridge", "serverInfo comes first, from the oscar bridge");
  if (!check(a.channels.has(SIG) && a.channels.has(CAM), `${SIG} and ${CAM} are advertised`)) return;
  const sig = a.channels.get(SIG), cam = a.channels.get(CAM);
  check(sig.encoding === "cdr" && sig.schemaEncoding === "omgidl" && sig.schemaName === "oscar::Bool",
        `${SIG}: cdr, omgidl, oscar::Bool (${sig.encoding}, ${sig.schemaEncoding}, ${sig.schemaName})`);
  check(cam.schemaName === "oscar::GvImage", `${CAM}: oscar::GvImage`);

  // The system's state (the registry's, as `oscar ps` shows it) is a channel too.
  if (check(a.channels.has(STATE) && a.channels.get(STATE).schemaName === "oscar::SystemState",
            `${STATE} is advertised as oscar::SystemState`)) {
    const stateSub = a.subscribe(STATE);
    await until(() => a.received.get(stateSub).length > 0, 5000);
    const state = (a.received.get(stateSub)[0] || {}).msg || {};
    const modules = (state.modules || []).map((m) => `${m.name}:${m.status}`).sort().join(" ");
    check(state.system === "viewed" && state.state === "running" &&
          modules === "arm:running camera:running plain_camera:running robot:running sources:running",
          `the last system state arrives on subscribing and decodes: ${state.system} ${state.state}, ${modules}`);
    a.client.unsubscribe(stateSub);
  }

  // 2. Subscribe to a Bool and an image topic; decode with only the advertised schema.
  const sigSub = a.subscribe(SIG), camSub = a.subscribe(CAM);
  const t0 = Date.now();
  await sleep(3000);
  const bools = a.received.get(sigSub), images = a.received.get(camSub);
  const steadyFrom = t0 + 1000, steadyTo = Date.now();
  figures.sig_hz_before = rateHz(bools, steadyFrom, steadyTo);
  figures.producer_hz_before = producerHz(bools.filter((m) => m.at >= steadyFrom));
  figures.bool_latency_ms = latencyMs(bools.filter((m) => m.at >= steadyFrom));
  figures.image_latency_ms = latencyMs(images.filter((m) => m.at >= steadyFrom));
  check(bools.length >= 50, `${bools.length} Bool messages in 3 s (50 Hz source)`);
  check(bools.every((m) => m.msg && !m.msg.error && m.msg.value === true && m.msg.header.source === "sig/out"),
        "every Bool decodes: value true, header.source sig/out");
  check(increasing(seqs(bools)), "Bool sequence numbers increase");
  check(images.length >= 20, `${images.length} images in 3 s (20 Hz source)`);
  check(images.every((m) => !m.msg.error && m.msg.dx === 640 && m.msg.dy === 480 && imageComplete(m)),
        "every image decodes complete: 640 x 480, its pixel pattern intact");
  check(increasing(seqs(images)), "image sequence numbers increase");
  const now = BigInt(Date.now()) * 1000000n;
  check(bools.every((m) => m.timestamp > now - 60000000000n && m.timestamp <= now),
        "receive timestamps are ns since the epoch, in the last minute");

  // 3. Unsubscribing stops the traffic.
  a.client.unsubscribe(sigSub);
  await sleep(300);  // what was in flight
  const afterUnsubscribe = bools.length;
  const imagesBefore = images.length;
  await sleep(1000);
  check(bools.length === afterUnsubscribe, `no Bool after unsubscribing (${bools.length - afterUnsubscribe} came)`);
  check(images.length > imagesBefore, "the image subscription goes on");
  a.client.unsubscribe(camSub);
  // Nothing is lost without a word: a gap in the Bool sequence is a drop the bridge reported to
  // this client (a Node.js client busy, e.g. compiling its decoder, can fall behind briefly).
  const lost = missing(seqs(bools));
  const told = reportedDrops(a, SIG);
  figures.healthy_client_bools = { received: bools.length, lost, told };
  check(lost <= told && lost <= 0.05 * bools.length,
        `the Bool messages this client did not get were dropped and reported (${lost} missing, ${told} reported)`);

  // 3b. Side channels in Foxglove's schemas, the system graph, converting only when subscribed.
  await checkSideChannels(a, { check, until, sleep, figures, imageComplete, expectJpeg: !process.argv.slice(0, process.argv.indexOf("--late")).includes("--no-jpeg") });

  // 4. A topic that appears later is advertised, served, and unadvertised when it goes.
  const child = spawn(lateCommand[0], lateCommand.slice(1), { stdio: "ignore" });
  const appeared = await until(() => a.channels.has(LATE), 20000);
  if (check(appeared, `${LATE}, appearing later, is advertised`)) {
    const lateId = a.channels.get(LATE).id;
    const lateSub = a.subscribe(LATE);
    await until(() => a.received.get(lateSub).length >= 3, 10000);
    check(a.received.get(lateSub).length >= 3 && a.received.get(lateSub).every((m) => m.msg.header.source === "late/out"),
          `its messages arrive and decode (${a.received.get(lateSub).length})`);
    child.kill("SIGTERM");
    check(await until(() => a.unadvertised.has(lateId), 15000), `${LATE} is unadvertised once its module stopped`);
  }
  child.kill("SIGKILL");

  // 5. A stalled client does not delay another client or the system; its drops are counted.
  const stalled = new Client("stalled");
  const b = new Client("b");
  await until(() => stalled.channels.has(CAM) && b.channels.has(SIG), 10000);
  const stalledCam = stalled.subscribe(CAM), stalledSig = stalled.subscribe(SIG);
  const bSig = b.subscribe(SIG);
  await sleep(1000);
  stalled.ws.pause();  // it reads nothing more: TCP buffers fill, then the bridge's queue
  const stallFrom = Date.now();
  await sleep(6000);
  const stallTo = Date.now();
  const bList = b.received.get(bSig).filter((m) => m.at >= stallFrom + 500 && m.at < stallTo);
  figures.sig_hz_while_stalled = rateHz(b.received.get(bSig), stallFrom + 500, stallTo);
  figures.producer_hz_while_stalled = producerHz(bList);
  figures.max_gap_ms_while_stalled = maxGapMs(bList);
  figures.bool_latency_ms_while_stalled = latencyMs(bList);
  check(figures.sig_hz_while_stalled >= 0.9 * figures.sig_hz_before,
        `the other client's Bool rate holds: ${figures.sig_hz_while_stalled.toFixed(1)} Hz while stalled, ` +
        `${figures.sig_hz_before.toFixed(1)} Hz before`);
  check(Math.abs(figures.producer_hz_while_stalled - 1000 / SIG_PERIOD_MS) < 5,
        `the producer's rate holds: ${figures.producer_hz_while_stalled.toFixed(1)} Hz (period ${SIG_PERIOD_MS} ms)`);
  check(consecutive(seqs(bList)), "the other client loses nothing");
  check(figures.max_gap_ms_while_stalled < 250, `its longest gap: ${figures.max_gap_ms_while_stalled} ms`);
  stalled.ws.resume();
  const camSeen = stalled.received.get(stalledCam);
  // Every image it missed was dropped by the bridge and reported to it (drops are reported once
  // a second; the newest message of a channel is never dropped, so each drop is a gap).
  await until(() => reportedDrops(stalled, CAM) > 0 && reportedDrops(stalled, CAM) === missing(seqs(camSeen)), 8000);
  const warning = stalled.statuses.find((s) => s.message.includes(CAM));
  check(warning && warning.level === 1 && /dropped the oldest/.test(warning.message),
        `the stalled client is told what it lost: ${warning ? warning.message : "no status"}`);
  const camSeqs = seqs(camSeen);
  figures.stalled_images = { received: camSeqs.length, lost: missing(camSeqs), told: reportedDrops(stalled, CAM) };
  check(increasing(camSeqs) && missing(camSeqs) > 0, "its images skip the dropped ones and stay in order");
  check(figures.stalled_images.told === figures.stalled_images.lost,
        `every image it missed was reported dropped (${figures.stalled_images.lost} missing, ${figures.stalled_images.told} reported)`);
  check(stalled.received.get(stalledSig).length > 0, "it still gets Bool messages after resuming");

  // 6. Configuration from Foxglove: only with --allow-config; malformed calls refused.
  await checkServices(a, args.configUrl, { check, until, sleep, Client, figures, rateHz });
  for (const c of [a, b, stalled]) check(c.errors.length === 0, `client ${c.name}: no errors ${c.errors.join("; ")}`);
  for (const c of [a, b, stalled]) c.close();
}

main()
  .catch((e) => check(false, `exception: ${e.stack || e}`))
  .finally(() => {
    console.log(JSON.stringify({ figures, failures: failures.length }));
    process.exit(failures.length ? 1 : 0);
  });
