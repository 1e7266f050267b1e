// Reads an MCAP file written by agnocast with readers agnocast did not write:
// @mcap/core's indexed reader (through the summary and indexes) and streamed
// reader (every record, CRCs checked), and decodes every message with
// @foxglove/rosmsg (the schema's .msg text) and @foxglove/rosmsg2-serialization
// (the CDR), comparing each with the values the writer says it wrote, and each
// definition the writer names with the .msg files it must hold word for word.
//   node check-mcap.mjs FILE.mcap EXPECTED.json
import { readFile } from "node:fs/promises";
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { parse } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";
import * as zstd from "@foxglove/wasm-zstd";
import lz4 from "@foxglove/wasm-lz4";

const [file, expectedFile] = process.argv.slice(2);
if (!file || !expectedFile) {
  console.error("usage: node check-mcap.mjs FILE.mcap EXPECTED.json");
  process.exit(2);
}

await zstd.isLoaded;
await lz4.isLoaded;
const decompressHandlers = {
  zstd: (buffer, size) => zstd.decompress(buffer, Number(size)),
  lz4: (buffer, size) => lz4(buffer, Number(size)),
};

let failures = 0;
function fail(message) {
  failures += 1;
  console.error(`FAIL: ${message}`);
}

// Compares a decoded value with the expected JSON value, field by field.
function compare(actual, expected, where) {
  // bool[] travels as bytes in agnocast's schema (a vector<bool> packs bits).
  if (typeof actual === "boolean" && typeof expected === "number") actual = Number(actual);
  if (typeof actual === "bigint") {
    if (actual !== BigInt(expected)) fail(`${where}: ${actual} != ${expected}`);
    return;
  }
  if (ArrayBuffer.isView(actual)) actual = Array.from(actual);
  if (Array.isArray(expected)) {
    if (!Array.isArray(actual) || actual.length !== expected.length) {
      fail(`${where}: length ${actual?.length} != ${expected.length}`);
      return;
    }
    expected.forEach((value, i) => compare(actual[i], value, `${where}[${i}]`));
    return;
  }
  if (expected !== null && typeof expected === "object") {
    const keys = Object.keys(expected);
    if (Object.keys(actual).length !== keys.length) {
      fail(`${where}: fields ${Object.keys(actual)} != ${keys}`);
    }
    for (const key of keys) compare(actual[key], expected[key], `${where}.${key}`);
    return;
  }
  if (typeof expected === "number" && !Number.isInteger(expected)) {
    // float32 fields decode to the float's exact value, the writer printed its shortest form
    if (Math.abs(actual - expected) > 1e-6 * Math.max(1, Math.abs(expected))) {
      fail(`${where}: ${actual} != ${expected}`);
    }
    return;
  }
  if (actual !== expected) fail(`${where}: ${JSON.stringify(actual)} != ${JSON.stringify(expected)}`);
}

const bytes = new Uint8Array(await readFile(file));
const { messages: expected, definitions } = JSON.parse(await readFile(expectedFile, "utf8"));

function decoderFor(schema) {
  if (schema.encoding !== "ros2msg") fail(`schema ${schema.name}: encoding ${schema.encoding}`);
  const text = new TextDecoder().decode(schema.data);
  return new MessageReader(parse(text, { ros2: true }));
}

function checkMessages(messages, channels, schemas, reader) {
  if (messages.length !== expected.length) {
    fail(`${reader}: ${messages.length} messages, expected ${expected.length}`);
  }
  const decoders = new Map();
  messages.forEach((message, i) => {
    const channel = channels.get(message.channelId);
    const want = expected[i];
    if (!want) return;
    if (channel.topic !== want.topic) fail(`${reader} #${i}: topic ${channel.topic} != ${want.topic}`);
    if (channel.messageEncoding !== "cdr") fail(`${channel.topic}: encoding ${channel.messageEncoding}`);
    if (!channel.metadata.get("offered_qos_profiles")?.startsWith("- history: 1")) {
      fail(`${channel.topic}: no offered_qos_profiles`);
    }
    if (message.logTime !== BigInt(want.log_time)) fail(`${reader} #${i}: log time ${message.logTime}`);
    if (!decoders.has(channel.schemaId)) decoders.set(channel.schemaId, decoderFor(schemas.get(channel.schemaId)));
    const value = decoders.get(channel.schemaId).readMessage(message.data);
    compare(value, want.value, `${reader} #${i} ${channel.topic}`);
  });
}

// Indexed: the footer, summary, chunk and message indexes, CRCs checked.
const readable = {
  size: async () => BigInt(bytes.length),
  read: async (offset, size) => bytes.subarray(Number(offset), Number(offset + size)),
};
const indexed = await McapIndexedReader.Initialize({ readable, decompressHandlers });
if (indexed.header.profile !== "ros2") fail(`profile ${indexed.header.profile}`);
if (!indexed.statistics) fail("no statistics");
if (indexed.chunkIndexes.length === 0) fail("no chunk indexes");
const indexedMessages = [];
for await (const message of indexed.readMessages({ validateCrcs: true })) indexedMessages.push(message);
checkMessages(indexedMessages, indexed.channelsById, indexed.schemasById, "indexed");
if (indexed.statistics && indexed.statistics.messageCount !== BigInt(expected.length)) {
  fail(`statistics: ${indexed.statistics.messageCount} messages`);
}

// Streamed: every record in file order, CRCs of chunks and data section checked.
const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true });
stream.append(bytes);
const streamed = [];
const channels = new Map();
const schemas = new Map();
const seen = new Set();
for (let record; (record = stream.nextRecord()); ) {
  seen.add(record.type);
  if (record.type === "Message") streamed.push(record);
  if (record.type === "Channel") channels.set(record.id, record);
  if (record.type === "Schema") schemas.set(record.id, record);
}
if (!stream.done()) fail("the streamed reader did not reach the end");
for (const type of ["Header", "Schema", "Channel", "Message", "DataEnd", "Statistics", "ChunkIndex", "SummaryOffset", "Footer"]) {
  if (!seen.has(type)) fail(`the streamed reader met no ${type} record`);
}
checkMessages(streamed, channels, schemas, "streamed");

// The standard types' schemas carry their .msg text whole, as rosbag2 writes
// it: PointCloud2's holds PointField's constants, which the parser sees.
let pointFieldSchemas = 0;
for (const schema of schemas.values()) {
  const definitions = parse(new TextDecoder().decode(schema.data), { ros2: true });
  const pointField = definitions.find((d) => /^sensor_msgs\/(msg\/)?PointField$/.test(d.name ?? ""));
  if (!pointField) continue;
  pointFieldSchemas += 1;
  const constant = pointField.definitions.find((d) => d.isConstant && d.name === "FLOAT32");
  if (!constant || Number(constant.value) !== 7) {
    fail(`schema ${schema.name}: PointField has no constant FLOAT32 = 7`);
  }
  if (pointField.definitions.filter((d) => d.isConstant).length !== 8) {
    fail(`schema ${schema.name}: PointField has not its 8 constants`);
  }
}
if (pointFieldSchemas === 0) fail("no schema uses sensor_msgs/PointField");

// A user type's definition is its .msg files as they are (constants, comments
// and blank lines kept), joined as rosbag2 joins them.
const separator = "=".repeat(80);
for (const want of definitions) {
  const schema = [...schemas.values()].find((s) => s.name === want.schema);
  if (!schema) {
    fail(`no schema ${want.schema}`);
    continue;
  }
  const text = new TextDecoder().decode(schema.data);
  const sections = text.split(`${separator}\n`);
  if (sections[0] !== want.own) fail(`${want.schema}: its own text differs from its .msg file:\n${sections[0]}`);
  for (const [name, own] of Object.entries(want.uses)) {
    const section = sections.find((s) => s.startsWith(`MSG: ${name}\n`));
    if (section === undefined) fail(`${want.schema}: no section MSG: ${name}`);
    else if (section !== `MSG: ${name}\n${own}`) fail(`${want.schema}: ${name}'s text differs from its .msg file`);
  }
  const parsed = parse(text, { ros2: true });
  const constant = parsed[0].definitions.find((d) => d.isConstant && d.name === "MODE_DRIVE");
  if (!constant || Number(constant.value) !== 1) fail(`${want.schema}: no constant MODE_DRIVE = 1`);
}

if (failures > 0) {
  console.error(`${file}: ${failures} failures`);
  process.exit(1);
}
console.log(`${file}: ${expected.length} messages read back by @mcap/core (indexed and streamed) and decoded by @foxglove/rosmsg2-serialization, constants seen, ${definitions.length} user definitions equal to their .msg files`);
