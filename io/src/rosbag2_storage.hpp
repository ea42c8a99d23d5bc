#pragma once
// The containers `ros2 bag record` writes, read into the one shape the log reader decodes
// (McapFile: schemas, channels, messages in time order):
// - an MCAP file (`-s mcap`, the default since ROS 2 Iron);
// - a SQLite file (`.db3`, rosbag2's sqlite3 storage, the default up to Humble): its `topics`
//   (id, name, type, serialization_format) and `messages` (topic_id, timestamp, data) tables,
//   the columns every rosbag2 release has written; messages compressed one by one with zstd
//   (`--compression-mode message`) are told by their zstd frame and decompressed;
// - a whole file compressed with zstd (`--compression-mode file`: `bag_0.db3.zstd`,
//   `bag_0.mcap.zstd`);
// - the bag's directory: its metadata.yaml names the storage and the files in order (a bag split
//   by `--max-bag-size` or `--max-bag-duration` is read whole); without one, every .db3, .mcap
//   and .zstd file in it, in the order of the numbers ending their names.
// Each type becomes a schema of encoding "ros2msg" named as the bag names it; each topic a
// channel of the bag's serialization format ("cdr"). Private to lampnav::io.

#include <string>
#include <vector>

#include "lampnav/io/mcap.hpp"

namespace lampnav::io {

// Reads `path`, whichever container it is (above). Throws InputError naming the file (and the
// table, record or field) for what cannot be read. `notes` says how a directory was read.
McapFile read_log_container(const std::string& path, std::vector<std::string>& notes);

// A rosbag2 SQLite database held in memory (a .db3 file's bytes); `source` names it in messages.
McapFile read_sqlite_bag_bytes(const std::string& bytes, const std::string& source);
// One file's bytes, MCAP or SQLite (a file compressed whole is decompressed by the reader of
// files, not here).
McapFile read_log_bytes(const std::string& bytes, const std::string& source);

}  // namespace lampnav::io
