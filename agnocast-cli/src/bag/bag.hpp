// agnocast-cli bag: record typed topics into an MCAP file (profile ros2, CDR
// messages, ros2msg schemas) and tell what a file holds. These commands work
// on the live system and on files, not through an InspectionSource.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "agnocast/mcap/records.hpp"
#include "cli.hpp"

namespace agnocast::cli {

void set_bag_command(CLI::App& app, Context& context);

// bag info FILE: the shape in agnocast-cli/README.md. Throws InputError for a
// file that cannot be read or is not MCAP.
nlohmann::json bag_info_json(const std::string& path);
std::string bag_info_table(const nlohmann::json& value);

struct BagRecordOptions {
  std::string output;  // a file, a directory (DIR/<timestamp>.mcap), or empty (./<timestamp>.mcap)
  bool all = false;
  std::vector<std::string> topics;
  mcap::Compression compression = mcap::Compression::Zstd;
  std::optional<std::uint64_t> max_size;  // bytes per file: then the next file starts
  std::optional<double> duration_s;
  bool json = false;  // the summary as one JSON object
};

// Records until SIGINT/SIGTERM or the duration; the summary goes to out, a
// live status line to status when it is a terminal. Throws InputError for a
// topic that does not exist or has no schema.
int bag_record(const BagRecordOptions& options, std::ostream& out);

struct BagPlayOptions {
  std::string path;
  double rate = 1.0;
  bool loop = false;
  std::vector<std::string> topics;  // empty: every topic
  double start_offset_s = 0;
};

// Publishes the file's messages with their original spacing (divided by
// rate). Throws InputError for a file it cannot read or play, naming why.
int bag_play(const BagPlayOptions& options, std::ostream& out);

// The .mcap path `output` names: a file as given, or a new one named after
// `unix_seconds` (local time) inside a directory (an existing one, or one
// ending in '/'; created).
std::string bag_output_path(const std::string& output, double unix_seconds);

}  // namespace agnocast::cli
