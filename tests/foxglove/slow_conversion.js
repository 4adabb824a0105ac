// A client of a bridge whose conversions are slowed down (its test hook
// --test-conversion-delay-ms): subscribes to a raw Bool topic, to side channels and to the
// system graph for 4 s (Foxglove's own client, @foxglove/ws-protocol), and prints as JSON what
// it received:
//
//   node slow_conversion.js --url ws://127.0.0.1:PORT --bool TOPIC --side TOPIC [--side TOPIC]
//
// {"bools_per_s": .., "max_bool_gap_ms": .., "side_per_s": {topic: ..},
//  "skipped": {topic: ..}, "converted": {topic: ..}} with the counters of the last graph; exits 2
// if a topic is not advertised within 10 s.
"use strict";
const WebSocket = require("ws");
const { FoxgloveClient } = require("@foxglove/ws-protocol");

const arg = (name) => process.argv[process.argv.indexOf(name) + 1];
const sides = process.argv.flatMap((a, i) => (a === "--side" ? [process.argv[i + 1]] : []));
const GRAPH = "foxglove/system/graph";
const ws = new WebSocket(arg("--url"), [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
const client = new FoxgloveClient({ ws });
const channels = new Map();
const topicOf = new Map();  // subscription id -> topic
const arrivals = new Map();  // topic -> arrival times (ms)
let graph;
let started = false;
const kSeconds = 4;

client.on("advertise", (list) => {
  for (const c of list) channels.set(c.topic, c.id);
  const topics = [arg("--bool"), GRAPH, ...sides];
  if (started || !topics.every((t) => channels.has(t))) return;
  started = true;
  for (const topic of topics) {
    topicOf.set(client.subscribe(channels.get(topic)), topic);
    arrivals.set(topic, []);
  }
  setTimeout(() => {
    const bools = arrivals.get(arg("--bool"));
    let gap = 0;
    for (let i = 1; i < bools.length; ++i) gap = Math.max(gap, bools[i] - bools[i - 1]);
    const counter = (key) => Object.fromEntries(sides.map((t) => {
      const s = ((graph && graph.side_channels) || []).find((x) => x.topic === t);
      return [t, s ? s[key] : null];
    }));
    console.log(JSON.stringify({
      bools_per_s: bools.length / kSeconds,
      max_bool_gap_ms: Math.round(gap),
      side_per_s: Object.fromEntries(sides.map((t) => [t, arrivals.get(t).length / kSeconds])),
      skipped: counter("skipped"),
      converted: counter("converted"),
    }));
    process.exit(0);
  }, kSeconds * 1000);
});
client.on("message", ({ subscriptionId, data }) => {
  const topic = topicOf.get(subscriptionId);
  if (!topic) return;
  arrivals.get(topic).push(performance.now());
  if (topic === GRAPH) graph = JSON.parse(Buffer.from(data.buffer, data.byteOffset, data.byteLength).toString("utf8"));
});
setTimeout(() => { if (!started) { console.log("topics not advertised within 10 s"); process.exit(2); } }, 10000);
