// Opens an MCAP file with the official TypeScript reader (@mcap/core's indexed reader), zstd
// chunks decompressed by fzstd. Returns the reader and a close function.
import { McapIndexedReader } from "@mcap/core";
import { decompress } from "fzstd";
import { open } from "node:fs/promises";

export async function openMcap(path) {
  const handle = await open(path, "r");
  const readable = {
    size: async () => BigInt((await handle.stat()).size),
    read: async (offset, size) => {
      const buf = new Uint8Array(Number(size));
      await handle.read(buf, 0, Number(size), Number(offset));
      return buf;
    },
  };
  try {
    const reader = await McapIndexedReader.Initialize({
      readable,
      decompressHandlers: { zstd: (buffer) => decompress(buffer) },
    });
    return { reader, close: () => handle.close() };
  } catch (err) {
    await handle.close();
    throw err;
  }
}
