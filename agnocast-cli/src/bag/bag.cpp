// agnocast-cli bag: record, info and play, wired into CLI11.
#include "bag/bag.hpp"

#include <CLI/CLI.hpp>
#include <memory>

#include "agnocast/naming.hpp"

namespace agnocast::cli {
namespace {

void set_record_command(CLI::App& bag, Context& context) {
  auto options = std::make_shared<BagRecordOptions>();
  auto compression = std::make_shared<std::string>("zstd");
  CLI::App* record = bag.add_subcommand(
      "record", "Record typed topics into an MCAP file (profile ros2, CDR) until SIGINT/SIGTERM");
  record->add_option(
      "-o,--output", options->output,
      "File to write, or directory for <timestamp>.mcap (default: ./<timestamp>.mcap)");
  record->add_flag("--all", options->all,
                   "Record every typed topic, including those that appear while recording");
  record->add_option("TOPIC", options->topics, "Topics to record")
      ->check(CLI::Validator([](std::string& name) { return topic_name_problem(name); }, "TOPIC",
                             "topic name"));
  record->add_option("--compression", *compression, "Chunk compression (default zstd)")
      ->check(CLI::IsMember({"zstd", "lz4", "none"}));
  record
      ->add_option("--max-size", options->max_size,
                   "Start a new file (NAME_1.mcap, ...) before one exceeds BYTES")
      ->check(CLI::PositiveNumber);
  record->add_option("--duration", options->duration_s, "Stop after SECONDS")
      ->check(CLI::PositiveNumber);
  bind_command(*record, context, {.stream = [&context, options, compression](std::ostream& out) {
    if (options->all == !options->topics.empty()) {
      throw InputError("bag record needs either --all or at least one TOPIC");
    }
    options->compression = *compression == "zstd"  ? mcap::Compression::Zstd
                           : *compression == "lz4" ? mcap::Compression::Lz4
                                                   : mcap::Compression::None;
    options->json = context.json;
    return bag_record(*options, out);
  }});
  record->get_option("--json")->description("Print the final summary as one JSON object");
}

void set_info_command(CLI::App& bag, Context& context) {
  auto path = std::make_shared<std::string>();
  CLI::App* info = bag.add_subcommand(
      "info", "Show what an MCAP file holds: duration, size, compression, topics, counts, rates");
  info->add_option("FILE", *path, "The .mcap file")->required();
  bind_command(*info, context,
               {.build = [path] { return bag_info_json(*path); }, .render = bag_info_table});
}

void set_play_command(CLI::App& bag, Context& context) {
  auto options = std::make_shared<BagPlayOptions>();
  CLI::App* play = bag.add_subcommand(
      "play", "Publish an MCAP file's messages on agnocast topics with their original spacing");
  play->add_option("FILE", options->path, "The .mcap file")->required();
  play->add_option("--rate", options->rate, "Speed factor (default 1)")->check(CLI::PositiveNumber);
  play->add_flag("--loop", options->loop, "Start over at the end, until SIGINT/SIGTERM");
  play->add_option("--topics", options->topics, "Only these topics");
  play->add_option("--start-offset", options->start_offset_s, "Skip the first SECONDS of the file")
      ->check(CLI::NonNegativeNumber);
  bind_command(*play, context,
               {.stream = [options](std::ostream& out) { return bag_play(*options, out); }});
}

}  // namespace

void set_bag_command(CLI::App& app, Context& context) {
  CLI::App* bag = app.add_subcommand("bag", "Record topics into MCAP files and inspect them");
  bag->require_subcommand(1);
  set_record_command(*bag, context);
  set_info_command(*bag, context);
  set_play_command(*bag, context);
}

}  // namespace agnocast::cli
