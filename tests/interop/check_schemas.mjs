// Parses every channel's JSON schema of an MCAP file as Foxglove does before it shows a topic, and
// validates each channel's first message against it. The foxglove.* channels must carry the
// official schema (@foxglove/schemas, pinned) exactly. Prints one JSON object; exits 1 when a
// topic would be dropped or a message does not validate.
//
// Foxglove (the last open-source Studio's parseJsonSchema, still in Lichtblick) drops a topic whose
// schema it cannot turn into fields: a `type` that is not one string (a union such as
// ["string", "null"]), an object without `properties`, an array without `items`.
import { createRequire } from "node:module";
import { isDeepStrictEqual } from "node:util";
import { openMcap } from "./open_mcap.mjs";

const official = createRequire(import.meta.url)("@foxglove/schemas/jsonschema");

function parse(schema, path) {
  if (schema.oneOf) {
    for (const alt of schema.oneOf)
      if (!("const" in alt)) throw new Error(`${path}: oneOf other than constants`);
    return;
  }
  if (typeof schema.type !== "string") throw new Error(`${path}: type ${JSON.stringify(schema.type)} is not one type`);
  switch (schema.type) {
    case "object":
      if (!schema.properties) throw new Error(`${path}: object without properties`);
      for (const [k, v] of Object.entries(schema.properties)) parse(v, `${path}.${k}`);
      return;
    case "array":
      if (!schema.items) throw new Error(`${path}: array without items`);
      parse(schema.items, `${path}[]`);
      return;
    case "string": case "number": case "integer": case "boolean":
      return;
    default:
      throw new Error(`${path}: unknown type ${schema.type}`);
  }
}

function validate(schema, value, path) {
  if (schema.oneOf) {
    if (!schema.oneOf.some((alt) => alt.const === value)) throw new Error(`${path}: ${value} is none of the constants`);
    return;
  }
  const t = schema.type;
  const ok =
    t === "object" ? value !== null && typeof value === "object" && !Array.isArray(value)
    : t === "array" ? Array.isArray(value)
    : t === "string" ? typeof value === "string"
    : t === "boolean" ? typeof value === "boolean"
    : t === "integer" ? Number.isInteger(value)
    : t === "number" ? typeof value === "number" : false;
  if (!ok) throw new Error(`${path}: ${JSON.stringify(value)} is not ${t}`);
  if (typeof value === "number") {
    if ("minimum" in schema && value < schema.minimum) throw new Error(`${path}: ${value} < ${schema.minimum}`);
    if ("maximum" in schema && value > schema.maximum) throw new Error(`${path}: ${value} > ${schema.maximum}`);
  }
  if (t === "object") {
    for (const k of schema.required ?? []) if (!(k in value)) throw new Error(`${path}: ${k} missing`);
    for (const [k, v] of Object.entries(value))
      if (schema.properties[k]) validate(schema.properties[k], v, `${path}.${k}`);
  }
  if (t === "array") value.forEach((v, i) => validate(schema.items, v, `${path}[${i}]`));
}

const { reader, close } = await openMcap(process.argv[2]);
const report = {};
let failed = false;
const schemas = {};
for (const ch of reader.channelsById.values()) {
  const s = reader.schemasById.get(ch.schemaId);
  const entry = { schema: s?.name ?? null, parsed: false, official: null, validated: false };
  report[ch.topic] = entry;
  try {
    if (s?.encoding !== "jsonschema") throw new Error(`schema encoding ${s?.encoding}`);
    const schema = JSON.parse(new TextDecoder().decode(s.data));
    parse(schema, s.name);
    entry.parsed = true;
    schemas[ch.id] = schema;
    if (s.name.startsWith("foxglove.")) {
      entry.official = isDeepStrictEqual(schema, official[s.name.slice("foxglove.".length)]);
      if (!entry.official) throw new Error("not the official schema");
    }
  } catch (err) {
    entry.error = err.message;
    failed = true;
  }
}
const seen = new Set();
for await (const msg of reader.readMessages()) {
  if (seen.has(msg.channelId) || !schemas[msg.channelId]) continue;
  seen.add(msg.channelId);
  const entry = report[reader.channelsById.get(msg.channelId).topic];
  try {
    validate(schemas[msg.channelId], JSON.parse(new TextDecoder().decode(msg.data)), entry.schema);
    entry.validated = true;
  } catch (err) {
    entry.error = err.message;
    failed = true;
  }
}
await close();
console.log(JSON.stringify(report));
process.exit(failed ? 1 : 0);
