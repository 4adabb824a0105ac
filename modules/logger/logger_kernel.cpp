#include "logger_kernel.hpp"

#include <algorithm>
#include <filesystem>
#include <regex>
#include <set>

#include <oscar/idl_texts.hpp>
#include <oscar/kernel_registry.hpp>

namespace oscar::modules {

void Logger::Params::describe(ParamSpec& spec) {
  spec.field("file", file, "the MCAP file to write (created on the first cue)").fixed();
  spec.field("inputs", inputs,
             "inputs to declare besides those the configuration wires: 'name, ...' (any cue type)")
      .fixed();
  spec.field("compression", compression, "chunk compression")
      .one_of({"zstd", "lz4", "none"})
      .fixed();
  spec.field("flush_every", flush_every, "write the open chunk when its oldest cue is this old");
}

std::vector<std::string> Logger::parse_inputs(const std::string& text) {
  static const std::regex name(R"(\s*([A-Za-z_][A-Za-z0-9_]*)\s*)");
  static const std::regex typed(R"(\s*([A-Za-z_][A-Za-z0-9_]*)\s*:.*)");
  std::vector<std::string> out;
  if (std::regex_match(text, std::regex(R"(\s*)"))) return out;
  std::set<std::string> names;
  std::size_t start = 0;
  while (start <= text.size()) {
    const auto comma = text.find(',', start);
    const auto item =
        text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    std::smatch m;
    if (std::regex_match(item, m, typed)) {
      throw std::invalid_argument("logger: parameter 'inputs': '" + item +
                                  "' names a type; give the input name only ('" + m[1].str() +
                                  "'): the logger takes each producer's type");
    }
    if (!std::regex_match(item, m, name)) {
      throw std::invalid_argument("logger: parameter 'inputs': '" + item +
                                  "' is not an input name (e.g. 'cam, flag')");
    }
    if (!names.insert(m[1]).second) {
      throw std::invalid_argument("logger: parameter 'inputs': input '" + m[1].str() +
                                  "' is named twice");
    }
    out.push_back(m[1]);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

Logger::Logger(KernelSetup& setup) {
  setup.params(params_);
  if (params_.file.empty()) {
    throw std::invalid_argument("logger: parameter 'file' must name the MCAP file to write");
  }
  std::set<std::string> names;
  for (const auto& name : setup.configured_inputs()) names.insert(name);
  for (const auto& name : parse_inputs(params_.inputs)) names.insert(name);
  if (names.empty()) {
    throw std::invalid_argument(
        "logger: nothing to record: wire inputs in the kernel's inputs: (e.g. inputs: { tags: "
        "mark_a/tags }) or name them in parameter 'inputs'");
  }
  for (const auto& name : names) {
    inputs_.push_back(&setup.raw_input(name, {.depth = 256, .transfer = Transfer::kPush}));
  }
}

Logger::~Logger() {
  try {
    if (writer_) writer_->close();
  } catch (const std::exception&) {  // nothing more can be done in a destructor
  }
}

void Logger::open() {
  mcap::WriterOptions o;
  o.compression = mcap::parse_compression(params_.compression);
  o.library = "oscar-logger";
  const auto dir = std::filesystem::path(params_.file).parent_path();
  if (!dir.empty()) std::filesystem::create_directories(dir);
  writer_ = std::make_unique<mcap::Writer>(params_.file, o);
  channels_.clear();
  schemas_.clear();
}

std::uint16_t Logger::channel(const RawCue& cue) {
  // The topic the cue travels on: oscar/cue/<kernel>/<channel> (from its header's source).
  const auto& source = cue.header().source();
  const auto topic = "oscar/cue/" + source;
  if (auto it = channels_.find(topic); it != channels_.end()) return it->second;
  std::uint16_t schema = 0;  // none: a type without an IDL text here
  if (auto s = schemas_.find(cue.type); s != schemas_.end()) {
    schema = s->second;
  } else if (auto idl = idl_texts().find(cue.type); idl != idl_texts().end()) {
    schema = schemas_[cue.type] =
        writer_->add_schema(cue.type, "omgidl", {idl->second.begin(), idl->second.end()});
  }
  std::map<std::string, std::string> meta{{"type", cue.type}, {"logger", "true"}};
  const auto slash = source.find('/');
  meta["kernel"] = source.substr(0, slash);
  if (slash != std::string::npos) meta["channel"] = source.substr(slash + 1);
  return channels_[topic] = writer_->add_channel(schema, topic, "cdr", meta);
}

void Logger::process(Cycle& cycle) {
  // This cycle's cues of all inputs in the order they arrived: the file is in log-time order.
  std::vector<Input<RawCue>::Received> items;
  for (auto* input : inputs_) {
    for (auto& r : input->take_new()) items.push_back(std::move(r));
  }
  std::stable_sort(items.begin(), items.end(),
                   [](const auto& a, const auto& b) { return a.received < b.received; });
  for (const auto& item : items) {
    if (!writer_) open();
    const auto& header = item.cue->header();
    mcap::MessageView m;
    m.channel_id = channel(*item.cue);
    m.sequence = static_cast<std::uint32_t>(header.seq());
    m.log_time = static_cast<std::uint64_t>(item.received);
    m.publish_time = header.stamps().empty() ? m.log_time : header.stamps()[0];
    m.data = item.cue->cdr;
    writer_->write(m);
    if (!unflushed_since_) unflushed_since_ = cycle.now();
  }
  if (writer_ && unflushed_since_ &&
      cycle.now() - unflushed_since_ >= static_cast<Stamp>(params_.flush_every.count())) {
    writer_->flush();
    unflushed_since_ = 0;
  }
}

void Logger::stub(Cycle& cycle) { process(cycle); }

void Logger::on_deactivate() {
  if (writer_) writer_->flush();
  unflushed_since_ = 0;
}

}  // namespace oscar::modules

OSCAR_REGISTER_KERNEL(oscar::modules::Logger, "logger")
