// Reads an MCAP file with the official TypeScript reader (@mcap/core's indexed reader) and prints
// what it found as JSON: profile, library, topics with schema and message counts, statistics,
// attachments with sizes. Exits 1 with the reader's error if it refuses the file.
import { openMcap } from "./open_mcap.mjs";

const path = process.argv[2];
let close = async () => {};
try {
  const opened = await openMcap(path);
  close = opened.close;
  const reader = opened.reader;
  const topics = {};
  for (const ch of reader.channelsById.values()) {
    topics[ch.topic] = {
      schema: reader.schemasById.get(ch.schemaId)?.name ?? null,
      encoding: ch.messageEncoding,
      count: 0,
    };
  }
  let lastLogTime = -1n;
  let ordered = true;
  let firstData = {};
  for await (const msg of reader.readMessages()) {
    const topic = reader.channelsById.get(msg.channelId).topic;
    topics[topic].count += 1;
    if (!(topic in firstData)) firstData[topic] = new TextDecoder().decode(msg.data);
    if (msg.logTime < lastLogTime) ordered = false;
    lastLogTime = msg.logTime;
  }
  const attachments = [];
  for await (const a of reader.readAttachments()) {
    attachments.push({ name: a.name, mediaType: a.mediaType ?? a.contentType, size: a.data.length });
  }
  const stats = reader.statistics;
  console.log(JSON.stringify({
    profile: reader.header.profile,
    library: reader.header.library,
    topics,
    firstData,
    logTimeOrdered: ordered,
    statistics: stats ? { messageCount: Number(stats.messageCount), chunkCount: stats.chunkCount } : null,
    attachments,
  }));
} catch (err) {
  console.error(`@mcap/core refused ${path}: ${err.message ?? err}`);
  process.exit(1);
} finally {
  await close();
}
