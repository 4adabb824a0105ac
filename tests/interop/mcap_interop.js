// The reference side of the MCAP interop test, with @mcap/core (npm).
//   node mcap_interop.js summary FILE   reads FILE twice, with McapStreamReader (every record,
//                                       CRCs validated) and McapIndexedReader (through the
//                                       summary and indexes), checks both agree, prints JSON
//   node mcap_interop.js write FILE     writes a known zstd-chunked file with McapWriter
"use strict";
const fs = require("fs");
const { McapStreamReader, McapIndexedReader, McapWriter } = require("@mcap/core");
const zstd = require("@foxglove/wasm-zstd");
const lz4 = require("@foxglove/wasm-lz4");

const decompressHandlers = {
  zstd: (data, size) => zstd.decompress(data, Number(size)),
  lz4: (data, size) => lz4(data, Number(size)),
};

function fail(message) {
  console.error(message);
  process.exit(1);
}

function print(schemas, channels, messages, sum, topics) {
  const sorted = {};
  for (const t of Object.keys(topics).sort()) sorted[t] = topics[t];
  console.log(JSON.stringify({ schemas, channels, messages, sum, topics: sorted }));
}

async function summary(file) {
  const bytes = fs.readFileSync(file);
  // 1. Every record in order, CRCs (chunks, data section, summary) validated.
  const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  stream.append(bytes);
  const schemas = new Set(), channels = new Map(), topics = {};
  let messages = 0, sum = 0, footer = false;
  for (let r; (r = stream.nextRecord()); ) {
    if (r.type === "Schema") schemas.add(r.id);
    if (r.type === "Channel") channels.set(r.id, r.topic);
    if (r.type === "Footer") footer = true;
    if (r.type === "Message") {
      ++messages;
      topics[channels.get(r.channelId)] = (topics[channels.get(r.channelId)] || 0) + 1;
      for (const x of r.data) sum += x;
    }
  }
  if (!stream.done() || !footer) fail(`${file}: the stream reader did not reach the footer`);
  // 2. Through the summary: statistics, chunk indexes and message indexes.
  const readable = {
    size: async () => BigInt(bytes.length),
    read: async (offset, size) => bytes.subarray(Number(offset), Number(offset + size)),
  };
  const indexed = await McapIndexedReader.Initialize({ readable, decompressHandlers });
  let indexedMessages = 0;
  for await (const m of indexed.readMessages()) { void m; ++indexedMessages; }
  const stats = indexed.statistics;
  if (!stats || Number(stats.messageCount) !== messages || indexedMessages !== messages) {
    fail(`${file}: stream reader saw ${messages} messages, indexed reader ${indexedMessages}, ` +
         `statistics say ${stats && stats.messageCount}`);
  }
  if (indexed.schemasById.size !== schemas.size || indexed.channelsById.size !== channels.size) {
    fail(`${file}: summary schemas/channels differ from the data section's`);
  }
  if (indexed.chunkIndexes.length !== Number(stats.chunkCount)) {
    fail(`${file}: ${indexed.chunkIndexes.length} chunk indexes, statistics say ${stats.chunkCount}`);
  }
  print(schemas.size, channels.size, messages, sum, topics);
}

async function write(file) {
  const fd = fs.openSync(file, "w");
  let position = 0n;
  const writable = {
    write: async (buffer) => { fs.writeSync(fd, buffer); position += BigInt(buffer.byteLength); },
    position: () => position,
  };
  const writer = new McapWriter({
    writable,
    chunkSize: 4096,
    compressChunk: (data) => ({ compression: "zstd", compressedData: zstd.compress(data) }),
  });
  await writer.start({ profile: "", library: "@mcap/core interop" });
  const a = await writer.registerSchema({ name: "oscar::Bool", encoding: "omgidl", data: Buffer.from("struct") });
  const b = await writer.registerSchema({ name: "oscar::GvImage", encoding: "omgidl", data: Buffer.from("mod") });
  const ch = [
    await writer.registerChannel({ schemaId: a, topic: "oscar/cue/a/out", messageEncoding: "cdr", metadata: new Map([["kernel", "a"]]) }),
    await writer.registerChannel({ schemaId: a, topic: "oscar/cue/b/out", messageEncoding: "cdr", metadata: new Map() }),
    await writer.registerChannel({ schemaId: b, topic: "oscar/cue/c/out", messageEncoding: "cdr", metadata: new Map([["qos", "reliable"]]) }),
  ];
  for (let i = 0; i < 1000; ++i) {
    const data = new Uint8Array(16 + (i % 200));
    for (let k = 0; k < data.length; ++k) data[k] = (i * 31 + k) & 0xff;
    await writer.addMessage({ channelId: ch[i % 3], sequence: i, logTime: BigInt(1000 + 10 * i),
                              publishTime: BigInt(500 + i), data });
  }
  await writer.end();
  fs.closeSync(fd);
}

(async () => {
  await zstd.isLoaded;
  await lz4.isLoaded;
  const [mode, file] = process.argv.slice(2);
  if (mode === "summary") await summary(file);
  else if (mode === "write") await write(file);
  else fail("usage: node mcap_interop.js summary FILE | write FILE");
})().catch((e) => fail(String(e && e.stack || e)));
