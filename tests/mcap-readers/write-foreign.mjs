// Writes an MCAP file as another recorder would, with writers agnocast did
// not write: @mcap/core's McapWriter and @foxglove/rosmsg2-serialization's
// MessageWriter. COUNT messages of a user type on /foreign_wheel, 50 ms
// apart; its definition is its .msg files joined as rosbag2 joins them; its
// channel says, in rosbag2's words, that it was published transient local at
// depth 100.
//   node write-foreign.mjs OUT.mcap COUNT pkg/msg/Type=ROOT.msg [pkg/Name=USED.msg ...]
// The values of message i are wheel(i); the test that plays the file
// expects the same ones.
import { readFile, writeFile } from "node:fs/promises";
import { McapWriter, TempBuffer } from "@mcap/core";
import { parse } from "@foxglove/rosmsg";
import { MessageWriter } from "@foxglove/rosmsg2-serialization";

const [out, countText, root, ...used] = process.argv.slice(2);
if (!out || !countText || !root) {
  console.error("usage: node write-foreign.mjs OUT.mcap COUNT pkg/msg/Type=ROOT.msg [pkg/Name=USED.msg ...]");
  process.exit(2);
}
const count = Number(countText);

const [rootName, rootFile] = root.split("=");
let definition = await readFile(rootFile, "utf8");
for (const entry of used) {
  const [name, file] = entry.split("=");
  definition += `${"=".repeat(80)}\nMSG: ${name}\n${await readFile(file, "utf8")}`;
}

function wheel(i) {
  return {
    header: { stamp: { sec: 1700000000 + i, nanosec: 1000 * i }, frame_id: `wheel/${i}` },
    tire: { pressure_kpa: 200 + i, brand: `brand number ${i} of the foreign file` },
    name: `w${i}`,
    radius: 0.25 * i,
    ticks: new Int32Array([i, -i, 2 * i]),
    speeds: new Float32Array(Array.from({ length: i % 5 }, (_, k) => k * 0.5)),
    tags: [`t${i}`],
    flags: [true, i % 2 === 0],
    enabled: i % 3 === 0,
    spares: [
      { pressure_kpa: i, brand: "" },
      { pressure_kpa: 7, brand: "spare" },
    ],
    axes: Array.from({ length: i % 4 }, (_, k) => ({ x: k, y: -k, z: i })),
    status: 1,
    code: 65 + (i % 26),
    odometer: 9007199254740992n + BigInt(i),
  };
}

const writer = new MessageWriter(parse(definition, { ros2: true }));
const buffer = new TempBuffer();
const mcap = new McapWriter({ writable: buffer });
await mcap.start({ profile: "ros2", library: "write-foreign.mjs" });
const schemaId = await mcap.registerSchema({
  name: rootName,
  encoding: "ros2msg",
  data: new TextEncoder().encode(definition),
});
const profiles =
  "- history: keep_last\n  depth: 100\n  reliability: reliable\n  durability: transient_local\n" +
  "  deadline:\n    sec: 9223372036\n    nsec: 854775807\n";
const channelId = await mcap.registerChannel({
  topic: "/foreign_wheel",
  messageEncoding: "cdr",
  schemaId,
  metadata: new Map([["offered_qos_profiles", profiles]]),
});
const start = 1700000000000000000n;
for (let i = 0; i < count; i++) {
  const time = start + BigInt(i) * 50000000n;
  await mcap.addMessage({
    channelId,
    sequence: i,
    logTime: time,
    publishTime: time,
    data: writer.writeMessage(wheel(i)),
  });
}
await mcap.end();
await writeFile(out, buffer.get());
console.log(`${out}: ${count} messages of ${rootName}`);
