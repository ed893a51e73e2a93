// Reads an MCAP file with @mcap/core, an implementation independent of ours and
// of the Python `mcap` package, both ways: indexed (summary, chunk indexes,
// message indexes) and streamed (every record in order), CRCs checked.
// Prints {indexed: {topic: count}, streamed: {topic: count}, statistics, metadata}.
// Usage: node mcap_check.mjs FILE.mcap   (with @mcap/core and @mcap/support installed)
import { open, readFile } from "node:fs/promises";
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { loadDecompressHandlers } from "@mcap/support";

const path = process.argv[2];
const decompressHandlers = await loadDecompressHandlers();
const handle = await open(path, "r");
const readable = {
  size: async () => BigInt((await handle.stat()).size),
  read: async (offset, size) => {
    const buf = new Uint8Array(Number(size));
    await handle.read(buf, 0, Number(size), Number(offset));
    return buf;
  },
};
const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });
const indexed = {};
for await (const msg of reader.readMessages({ validateCrcs: true })) {
  const topic = reader.channelsById.get(msg.channelId).topic;
  indexed[topic] = (indexed[topic] ?? 0) + 1;
}
const metadata = [];
for await (const m of reader.readMetadata()) metadata.push(m.name);
await handle.close();

const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true });
stream.append(await readFile(path));
const channels = new Map();
const streamed = {};
let footer = false;
for (let rec; (rec = stream.nextRecord()); ) {
  if (rec.type === "Channel") channels.set(rec.id, rec.topic);
  else if (rec.type === "Message") {
    const topic = channels.get(rec.channelId);
    streamed[topic] = (streamed[topic] ?? 0) + 1;
  } else if (rec.type === "Footer") footer = true;
}
console.log(
  JSON.stringify({
    indexed,
    streamed,
    footer,
    done: stream.done(),
    statistics: Number(reader.statistics?.messageCount ?? -1),
    metadata,
  }),
);
