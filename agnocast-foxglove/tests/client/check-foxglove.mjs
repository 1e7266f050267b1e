// Checks agnocast-foxglove with Foxglove's own client and decoders, against
// the topics foxglove_peer publishes (foxglove-vm-test starts them all):
//   node check-foxglove.mjs URL RECEIVED_FILE FAST_WINDOWS_FILE SERVER_PID
// Prints each step; exit 0 when every check held, 1 with the reason otherwise.
import { parse } from "@foxglove/rosmsg";
import { MessageReader, MessageWriter } from "@foxglove/rosmsg2-serialization";
import wsProtocol from "@foxglove/ws-protocol";
import { execFileSync } from "node:child_process";
import fs from "node:fs";
import WebSocket from "ws";

const { FoxgloveClient } = wsProtocol; // a CommonJS package
const [url, receivedFile, fastFile, serverPid] = process.argv.slice(2);
const subprotocol = FoxgloveClient.SUPPORTED_SUBPROTOCOL;

function fail(message) {
  console.error(`check-foxglove: FAIL: ${message}`);
  process.exit(1);
}
function step(message) {
  console.log(`check-foxglove: ${message}`);
}
const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));
async function waitFor(what, seconds, condition) {
  const end = Date.now() + seconds * 1000;
  while (!condition()) {
    if (Date.now() > end) fail(`timed out after ${seconds} s waiting for ${what}`);
    await sleep(20);
  }
}
function rssKiB(pid) {
  const line = fs.readFileSync(`/proc/${pid}/status`, "utf8").match(/^VmRSS:\s+(\d+)/m);
  return Number(line[1]);
}
function topicInfo(topic) {
  return JSON.parse(execFileSync("agnocast-cli", ["topic", "info", topic, "--json"], { encoding: "utf8" }));
}
function rawSocket() {
  const ws = new WebSocket(url, [subprotocol]);
  ws.statuses = [];
  ws.frames = 0;
  ws.opened = false;
  ws.closeCode = undefined;
  ws.on("open", () => (ws.opened = true));
  ws.on("close", (code) => (ws.closeCode = code));
  ws.on("error", () => {});
  ws.on("message", (data, isBinary) => {
    if (isBinary) {
      ws.frames++;
    } else {
      const message = JSON.parse(data.toString());
      if (message.op === "status") ws.statuses.push(message);
      if (message.op === "advertise") ws.channels = message.channels;
    }
  });
  return ws;
}

// 1. Connect (the server may still be starting), see serverInfo and the channels.
let client;
let serverInfo;
const channels = new Map(); // topic -> channel
const errors = [];
const received = new Map(); // subscription id -> decoded messages
const readers = new Map(); // subscription id -> MessageReader
let timeFrames = 0;
let lastTime = 0n;
for (let attempt = 0; ; attempt++) {
  const ws = new WebSocket(url, [subprotocol]);
  const opened = await new Promise((resolve) => {
    ws.on("open", () => resolve(true));
    ws.on("error", () => resolve(false));
  });
  if (opened) {
    client = new FoxgloveClient({ ws });
    break;
  }
  if (attempt > 100) fail(`cannot connect to ${url}`);
  await sleep(100);
}
client.on("serverInfo", (info) => (serverInfo = info));
client.on("advertise", (list) => list.forEach((channel) => channels.set(channel.topic, channel)));
client.on("unadvertise", (ids) => {
  for (const [topic, channel] of channels) if (ids.includes(channel.id)) channels.delete(topic);
});
client.on("status", (status) => {
  if (status.level === 2) errors.push(status.message);
});
client.on("time", (time) => {
  timeFrames++;
  lastTime = time.timestamp;
});
client.on("message", ({ subscriptionId, timestamp, data }) => {
  const reader = readers.get(subscriptionId);
  const list = received.get(subscriptionId);
  list.push({ timestamp, message: reader.readMessage(data) });
});
// FoxgloveClient attached its handlers after the socket opened: the open
// event is past, the server's first messages are not.
await waitFor("serverInfo", 10, () => serverInfo !== undefined);
if (!serverInfo.capabilities.includes("clientPublish") || !serverInfo.capabilities.includes("time")) {
  fail(`capabilities ${JSON.stringify(serverInfo.capabilities)}`);
}
if (!serverInfo.supportedEncodings.includes("cdr")) fail("cdr is not a supported encoding");
await waitFor("/fg_points, /fg_chatter and /fg_fast advertised", 15, () =>
  ["/fg_points", "/fg_chatter", "/fg_fast"].every((topic) => channels.has(topic)),
);
for (const [topic, type] of [
  ["/fg_points", "sensor_msgs/msg/PointCloud2"],
  ["/fg_chatter", "std_msgs/msg/String"],
]) {
  const channel = channels.get(topic);
  if (channel.encoding !== "cdr" || channel.schemaEncoding !== "ros2msg" || channel.schemaName !== type) {
    fail(`channel ${topic}: ${JSON.stringify(channel)}`);
  }
}
const pointsSchema = channels.get("/fg_points").schema;
for (const dependency of ["MSG: std_msgs/Header", "MSG: builtin_interfaces/Time", "MSG: sensor_msgs/PointField"]) {
  if (!pointsSchema.includes(dependency)) fail(`PointCloud2's schema lacks ${dependency}:\n${pointsSchema}`);
}
step(`serverInfo and ${channels.size} channels with their schemas`);

// 2. Subscribe and decode what the peer published.
function subscribe(topic) {
  const channel = channels.get(topic);
  const id = client.subscribe(channel.id);
  readers.set(id, new MessageReader(parse(channel.schema, { ros2: true })));
  received.set(id, []);
  return id;
}
const pointsId = subscribe("/fg_points");
const chatterId = subscribe("/fg_chatter");
await waitFor("5 messages on each topic", 15, () =>
  received.get(pointsId).length >= 5 && received.get(chatterId).length >= 5,
);
const now = BigInt(Date.now()) * 1000000n;
for (const { timestamp, message } of received.get(chatterId)) {
  if (!/^hello \d+$/.test(message.data)) fail(`/fg_chatter data ${JSON.stringify(message.data)}`);
  if (timestamp > now || now - timestamp > 10000000000n) fail(`/fg_chatter timestamp ${timestamp}, now ${now}`);
}
for (const { message } of received.get(pointsId)) {
  const n = message.header.stamp.sec;
  const values = new Float32Array(message.data.buffer.slice(message.data.byteOffset, message.data.byteOffset + 12));
  if (message.header.frame_id !== "lidar" || message.header.stamp.nanosec !== 500 || n < 1 ||
      message.height !== 1 || message.width !== 3 || message.point_step !== 4 || message.row_step !== 12 ||
      message.fields.length !== 1 || message.fields[0].name !== "x" || message.fields[0].datatype !== 7 ||
      message.is_dense !== true || message.data.length !== 12 ||
      values[0] !== n || values[1] !== n + 0.5 || values[2] !== n + 1) {
    fail(`/fg_points message ${JSON.stringify({ ...message, data: Array.from(values) })}`);
  }
}
if (timeFrames === 0 || now - lastTime > 10000000000n) fail(`time frames: ${timeFrames}, last ${lastTime}`);
step(`decoded ${received.get(pointsId).length} PointCloud2 and ${received.get(chatterId).length} String messages; ${timeFrames} time frames`);

// 3. clientPublish onto /fg_from_client, which the peer subscribes to.
const publishChannel = client.advertise({ topic: "/fg_from_client", encoding: "cdr", schemaName: "std_msgs/msg/String" });
const writer = new MessageWriter(parse("string data", { ros2: true }));
const sent = [];
for (let i = 1; i <= 5; i++) {
  sent.push(`from foxglove ${i}`);
  client.sendMessage(publishChannel, writer.writeMessage({ data: sent[sent.length - 1] }));
  await sleep(50);
}
const readReceived = () => (fs.existsSync(receivedFile) ? fs.readFileSync(receivedFile, "utf8").split("\n").filter(Boolean) : []);
await waitFor("the peer to receive the published messages", 10, () => readReceived().length >= sent.length);
if (JSON.stringify(readReceived()) !== JSON.stringify(sent)) fail(`peer received ${JSON.stringify(readReceived())}`);
if (errors.length > 0) fail(`error statuses: ${JSON.stringify(errors)}`);
step(`published ${sent.length} messages through clientPublish; the agnocast subscriber got them`);

// 4. 100 malformed frames: each answered by an error status, the connection stays, others are served.
const bad = rawSocket();
await waitFor("a second connection", 10, () => bad.opened);
const malformed = [
  "not json",
  "{",
  "[]",
  '{"op":"fly"}',
  '{"op":"subscribe"}',
  '{"op":"subscribe","subscriptions":[{"id":1,"channelId":999999}]}',
  '{"op":"advertise","channels":[{"id":1,"topic":"/fg_chatter","encoding":"json","schemaName":"x"}]}',
  Buffer.from([0xff, 1, 2]),
  Buffer.from([0x01, 0, 0]),
  Buffer.from([0x01, 77, 0, 0, 0, 0, 1, 0, 0]),
];
for (let i = 0; i < 100; i++) bad.send(malformed[i % malformed.length]);
await waitFor("100 error statuses", 20, () => bad.statuses.filter((s) => s.level === 2).length >= 100);
if (bad.closeCode !== undefined) fail(`the malformed-frame connection was closed (${bad.closeCode})`);
const chatterBefore = received.get(chatterId).length;
await waitFor("more messages for the first client", 10, () => received.get(chatterId).length >= chatterBefore + 3);
step("100 malformed frames: 100 error statuses, the connection stays, the first client is still served");

// 5. An oversized frame closes that connection (1009) only.
const big = rawSocket();
await waitFor("a third connection", 10, () => big.opened);
big.send(Buffer.alloc(9 << 20));
await waitFor("the oversized frame's connection to close", 20, () => big.closeCode !== undefined);
// 1009 (message too big) when the server's close frame arrives before it
// drops the socket, 1006 when the client is still sending and the frame is lost.
if (big.closeCode !== 1009 && big.closeCode !== 1006) fail(`oversized frame: close code ${big.closeCode}`);
const chatterAfterBig = received.get(chatterId).length;
await waitFor("more messages after the oversized frame", 10, () => received.get(chatterId).length >= chatterAfterBig + 3);
step(`a 9 MiB frame closed its connection (${big.closeCode}); the others are served`);

// 6. --max-clients 4: two more connect, the fifth is refused with 503.
await sleep(200); // the closed connection leaves the server's count
const third = rawSocket();
const fourth = rawSocket();
await waitFor("connections 3 and 4", 10, () => third.opened && fourth.opened);
const refused = await new Promise((resolve) => {
  const fifth = new WebSocket(url, [subprotocol]);
  fifth.on("open", () => resolve("opened"));
  fifth.on("unexpected-response", (request, response) => resolve(response.statusCode));
  fifth.on("error", () => {});
});
if (refused !== 503) fail(`the fifth connection: ${refused}, not refused with 503`);
third.close();
fourth.close();
await waitFor("connections 3 and 4 to close", 10, () => third.closeCode !== undefined && fourth.closeCode !== undefined);
step("the fifth connection was refused with HTTP 503");

// 7. A client that stops reading: the 1 kHz publisher keeps the pace and
// the publish() cost it had while the client read, the server holds no entry
// and does not grow; the kernel counts the stalled client's drops.
const windows = () => fs.readFileSync(fastFile, "utf8").split("\n").filter(Boolean).map((line) => JSON.parse(line));
const median = (list) => [...list].sort((a, b) => a - b)[Math.floor(list.length / 2)];
const slow = rawSocket();
await waitFor("the slow connection", 10, () => slow.opened && slow.channels !== undefined);
const fastChannel = slow.channels.find((channel) => channel.topic === "/fg_fast");
slow.send(JSON.stringify({ op: "subscribe", subscriptions: [{ id: 1, channelId: fastChannel.id }] }));
await waitFor("the slow client's first message", 10, () => slow.frames > 0);
const readingStart = windows().length;
await waitFor("4 publisher windows while the client reads", 10, () => windows().length >= readingStart + 5);
const baseline = windows().slice(readingStart + 1);
const rssBefore = rssKiB(serverPid);
slow._socket.pause(); // reads nothing more: the server's socket buffer fills
const stallStart = windows().length;
const chatterBeforeStall = received.get(chatterId).length;
const samples = [];
for (let i = 0; i < 6; i++) {
  await sleep(1000);
  const info = topicInfo("/fg_fast");
  const ours = info.subscribers.filter((s) => s.node === "agnocast_foxglove");
  if (ours.length !== 1) fail(`/fg_fast subscribers: ${JSON.stringify(info.subscribers)}`);
  samples.push(ours[0]);
}
const server = samples[samples.length - 1];
const previous = samples[samples.length - 2];
const maxHeld = Math.max(...samples.map((s) => s.held));
const during = windows().slice(stallStart + 1);
const rssAfter = rssKiB(serverPid);
if (during.length < 4) fail(`only ${during.length} publisher windows during the stall`);
const rate = (list) => (list[list.length - 1].published - list[0].published) / ((list.length - 1) * 0.5);
const baseP50 = median(baseline.map((w) => w.p50_us));
const stallP50 = median(during.map((w) => w.p50_us));
step(`publisher: ${rate(baseline).toFixed(0)}/s, publish() p50 ${baseP50} us with the client reading; ` +
     `${rate(during).toFixed(0)}/s, p50 ${stallP50} us with it stalled`);
step(`server subscriber: held at most ${maxHeld} (${server.held} at the end), dropped ${server.dropped}, received ${server.received}; ` +
     `server RSS ${rssBefore} -> ${rssAfter} KiB`);
// One receive takes at most the subscription's depth (16), each released after its callback.
if (maxHeld > 16) fail(`the server held ${maxHeld} entries of the stalled client's topic`);
// Stalled: nothing more taken, and what is held stays as it was (the last
// messages' releases, which the library sends with its next receive).
if (server.received !== previous.received || server.held !== previous.held) {
  fail(`still taking or holding messages for the stalled client: ${JSON.stringify(samples)}`);
}
if (server.dropped === 0) fail("no drop counted for the stalled client");
if (rate(during) < 0.8 * rate(baseline)) fail("the publisher slowed down while the client stalled");
if (stallP50 > 3 * baseP50 + 50) fail("publish() got slower while the client stalled");
if (rssAfter - rssBefore > 64 * 1024) fail("the server's memory grew by more than 64 MiB");
if (received.get(chatterId).length < chatterBeforeStall + 20) fail("the first client was not served during the stall");
step("a stalled client costs the publisher nothing; its losses are counted");

slow.terminate();
bad.close();
client.close();
step("PASS");
process.exit(0);
