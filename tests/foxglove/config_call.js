// One call of the bridge's service oscar/config with Foxglove's own client
// (@foxglove/ws-protocol), as a Foxglove user's Service Call panel makes it:
//
//   node config_call.js --url ws://127.0.0.1:PORT --request '{"module": ..., "command": ...}'
//
// Prints the answer; exits 0 on a response, 1 on a call failure, 2 if the server offers no
// oscar/config or does not answer within 10 s.
"use strict";
const WebSocket = require("ws");
const { FoxgloveClient } = require("@foxglove/ws-protocol");

const arg = (name) => process.argv[process.argv.indexOf(name) + 1];
const ws = new WebSocket(arg("--url"), [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
const client = new FoxgloveClient({ ws });
const done = (code, text) => { console.log(text); process.exit(code); };

client.on("serverInfo", (info) => {
  if (!info.capabilities.includes("services")) done(2, "no services offered");
});
client.on("advertiseServices", (services) => {
  const service = services.find((s) => s.name === "oscar/config");
  if (!service) return done(2, "no oscar/config advertised");
  client.sendServiceCallRequest({ serviceId: service.id, callId: 1, encoding: "json",
                                  data: new Uint8Array(Buffer.from(arg("--request"))) });
});
client.on("serviceCallResponse", (r) => done(0, `response ${Buffer.from(r.data).toString("utf8")}`));
client.on("serviceCallFailure", (f) => done(1, `failure ${f.message}`));
setTimeout(() => done(2, "no answer within 10 s"), 10000);
