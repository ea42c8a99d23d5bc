// Serializes each ROS 2 message the live node reads or writes with Foxglove's CDR serializer
// (@foxglove/rosmsg2-serialization) from ROS 2 Humble's definitions (@foxglove/rosmsg-msgs-common),
// and compares the bytes with lampnav's, byte for byte.
//
//   node ros2_messages.mjs CASES.json
//
// CASES.json: [{ "type": "geometry_msgs/msg/Twist", "message": {...}, "hex": "0001..." }, ...]
// (stamps as { "sec", "nanosec" }; uint8[] data as hex in "data_hex"). Prints one line per case
// and exits 1 on the first difference.
import { MessageWriter } from "@foxglove/rosmsg2-serialization";
import { definitions } from "./ros2_definitions.mjs";
import { readFileSync } from "node:fs";

// "pkg/msg/Name" is "pkg/Name" in the definitions package.
const key = (type) => type.replace("/msg/", "/");

// uint8[] fields travel as hex strings named *_hex.
function revive(v) {
  if (Array.isArray(v)) return v.map(revive);
  if (v && typeof v === "object") {
    const o = {};
    for (const [k, x] of Object.entries(v)) {
      if (k.endsWith("_hex")) o[k.slice(0, -4)] = Uint8Array.from(Buffer.from(x, "hex"));
      else o[k] = revive(x);
    }
    return o;
  }
  return v;
}

const cases = JSON.parse(readFileSync(process.argv[2], "utf8"));
let failed = 0;
for (const c of cases) {
  const writer = new MessageWriter(definitions(key(c.type)));
  const theirs = Buffer.from(writer.writeMessage(revive(c.message))).toString("hex");
  if (theirs === c.hex) {
    console.log(`same ${c.type} (${theirs.length / 2} bytes)`);
    continue;
  }
  failed++;
  let at = 0;
  while (at < theirs.length && theirs[at] === c.hex[at]) at++;
  console.log(
    `DIFFERENT ${c.type}: lampnav ${c.hex.length / 2} bytes, Foxglove ${theirs.length / 2}; ` +
      `first difference at byte ${Math.floor(at / 2)}\n  lampnav  ${c.hex}\n  foxglove ${theirs}`,
  );
}
process.exit(failed ? 1 : 0);
