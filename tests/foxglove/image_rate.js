// A client of a bridge started with --image-rate R (Foxglove's own client, @foxglove/ws-protocol):
// subscribes to an image topic and to a Bool topic for 4 s and prints what it received as JSON:
//
//   node image_rate.js --url ws://127.0.0.1:PORT --image TOPIC --bool TOPIC
//
// {"images_per_s": .., "bools_per_s": .., "told": true|false}; exits 2 if a topic is not
// advertised within 10 s.
"use strict";
const WebSocket = require("ws");
const { FoxgloveClient } = require("@foxglove/ws-protocol");

const arg = (name) => process.argv[process.argv.indexOf(name) + 1];
const ws = new WebSocket(arg("--url"), [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
const client = new FoxgloveClient({ ws });
const channels = new Map();
const counts = new Map();
let told = false;
let started = false;
const kSeconds = 4;

client.on("advertise", (list) => {
  for (const c of list) channels.set(c.topic, c.id);
  if (started || !channels.has(arg("--image")) || !channels.has(arg("--bool"))) return;
  started = true;
  for (const topic of [arg("--image"), arg("--bool")]) {
    counts.set(client.subscribe(channels.get(topic)), 0);
  }
  setTimeout(() => {
    const [images, bools] = [...counts.values()];
    console.log(JSON.stringify({ images_per_s: images / kSeconds, bools_per_s: bools / kSeconds, told }));
    process.exit(0);
  }, kSeconds * 1000);
});
client.on("message", ({ subscriptionId }) => counts.set(subscriptionId, counts.get(subscriptionId) + 1));
client.on("status", (s) => { if (s.message.includes("--image-rate")) told = true; });
setTimeout(() => { if (!started) { console.log("topics not advertised within 10 s"); process.exit(2); } }, 10000);
