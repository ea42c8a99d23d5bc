// ROS 2 Humble's message definitions (@foxglove/rosmsg-msgs-common) as Foxglove's CDR serializer
// takes them: a type's definition with every type it uses, the root first.
import { ros2humble } from "@foxglove/rosmsg-msgs-common";

export function definitions(type) {
  const out = [];
  const seen = new Set();
  const visit = (name) => {
    if (seen.has(name)) return;
    seen.add(name);
    const def = ros2humble[name];
    if (!def) throw new Error(`no definition of ${name}`);
    out.push(def);
    for (const f of def.definitions) if (f.isComplex) visit(f.type);
  };
  visit(type);
  return out;
}
