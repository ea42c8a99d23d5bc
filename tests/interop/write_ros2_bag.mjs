// Writes a ROS 2 bag (MCAP, profile ros2, schema encoding ros2msg, message encoding cdr) of a
// lampnav mission log with independent code: the official TypeScript MCAP reader and writer
// (@mcap/core), Foxglove's CDR serializer for ROS 2 (@foxglove/rosmsg2-serialization) and the
// ROS 2 Humble message definitions (@foxglove/rosmsg-msgs-common).
//
//   node write_ros2_bag.mjs MISSION.mcap BAG.mcap SEMI_AXIS
//
// The wheels become nav_msgs/msg/Odometry on /odom, integrated by the midpoint rule as ROS's
// diff_drive_controller does; the images become sensor_msgs/msg/CompressedImage on
// /ceiling_camera/image/compressed and /omni_camera/image/compressed. Header stamps are the
// capture times, log times the arrival times.
import { McapWriter } from "@mcap/core";
import { MessageWriter } from "@foxglove/rosmsg2-serialization";
import { definitions } from "./ros2_definitions.mjs";
import { open } from "node:fs/promises";
import { openMcap } from "./open_mcap.mjs";

const [input, output, semiAxisText] = process.argv.slice(2);
const semiAxis = Number(semiAxisText);
if (!input || !output || !(semiAxis > 0)) {
  console.error("usage: node write_ros2_bag.mjs MISSION.mcap BAG.mcap SEMI_AXIS");
  process.exit(2);
}

// The .msg text rosbag2 stores as the schema: the root's fields, then each dependency after a
// separator line.
function schemaText(type) {
  const field = (f) => {
    if (f.isConstant) return `${f.type} ${f.name}=${f.valueText ?? f.value}`;
    const t = f.type === "time" ? "builtin_interfaces/Time" : f.type;
    const array = f.isArray ? `[${f.arrayLength ?? ""}]` : "";
    return `${t}${array} ${f.name}`;
  };
  return definitions(type)
    .map((d, i) => {
      const body = d.definitions.map(field).join("\n");
      return i === 0 ? body : `${"=".repeat(80)}\nMSG: ${d.name}\n${body}`;
    })
    .join("\n");
}

function time(ns) {
  return { sec: Number(ns / 1_000_000_000n), nanosec: Number(ns % 1_000_000_000n) };
}

function stampNs(j) {
  return BigInt(j.timestamp.sec) * 1_000_000_000n + BigInt(j.timestamp.nsec);
}

const file = await open(output, "w");
let position = 0n;
const writable = {
  write: async (buffer) => {
    await file.write(buffer);
    position += BigInt(buffer.byteLength);
  },
  position: () => position,
};
const writer = new McapWriter({ writable, useChunks: true, chunkSize: 1024 * 1024 });
await writer.start({ profile: "ros2", library: "write_ros2_bag.mjs (@mcap/core)" });

const types = {
  odom: "nav_msgs/Odometry",
  image: "sensor_msgs/CompressedImage",
};
const writers = {};
const schemaIds = {};
for (const [key, type] of Object.entries(types)) {
  writers[key] = new MessageWriter(definitions(type));
  schemaIds[key] = await writer.registerSchema({
    name: type.replace("/", "/msg/"),
    encoding: "ros2msg",
    data: new TextEncoder().encode(schemaText(type)),
  });
}
const channel = async (topic, key) =>
  writer.registerChannel({ topic, schemaId: schemaIds[key], messageEncoding: "cdr", metadata: new Map() });
const channels = {
  "/wheels": await channel("/odom", "odom"),
  "/ceiling_camera/image": await channel("/ceiling_camera/image/compressed", "image"),
  "/omni_camera/image": await channel("/omni_camera/image/compressed", "image"),
};
const sequences = new Map();

const { reader, close } = await openMcap(input);
let x = 0, y = 0, yaw = 0, last = null, count = 0;
for await (const m of reader.readMessages()) {
  const topic = reader.channelsById.get(m.channelId).topic;
  if (!(topic in channels)) continue;
  const j = JSON.parse(new TextDecoder().decode(m.data));
  let message, key;
  if (topic === "/wheels") {
    if (last) {
      const dl = j.left - last.left, dr = j.right - last.right;
      const ds = 0.5 * (dl + dr), dyaw = (dr - dl) / (2 * semiAxis);
      x += ds * Math.cos(yaw + dyaw / 2);
      y += ds * Math.sin(yaw + dyaw / 2);
      yaw = Math.atan2(Math.sin(yaw + dyaw), Math.cos(yaw + dyaw));
    }
    last = j;
    key = "odom";
    message = {
      header: { stamp: time(stampNs(j)), frame_id: "odom" },
      child_frame_id: "base_link",
      pose: {
        pose: {
          position: { x, y, z: 0 },
          orientation: { x: 0, y: 0, z: Math.sin(yaw / 2), w: Math.cos(yaw / 2) },
        },
        covariance: new Array(36).fill(0),
      },
      twist: {
        twist: { linear: { x: 0, y: 0, z: 0 }, angular: { x: 0, y: 0, z: 0 } },
        covariance: new Array(36).fill(0),
      },
    };
  } else {
    key = "image";
    message = {
      header: { stamp: time(stampNs(j)), frame_id: j.frame_id },
      format: j.format,
      data: Uint8Array.from(Buffer.from(j.data, "base64")),
    };
  }
  const channelId = channels[topic];
  const sequence = sequences.get(channelId) ?? 0;
  sequences.set(channelId, sequence + 1);
  await writer.addMessage({
    channelId,
    sequence,
    logTime: m.logTime,
    publishTime: m.logTime,
    data: writers[key].writeMessage(message),
  });
  count += 1;
}
await close();
await writer.end();
await file.close();
console.log(JSON.stringify({ messages: count }));
