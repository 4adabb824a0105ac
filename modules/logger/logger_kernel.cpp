#include "logger_kernel.hpp"

#include <algorithm>
#include <filesystem>
#include <regex>
#include <set>

#include <oscar/cue_type_info.hpp>
#include <oscar/cue_types.hpp>
#include <oscar/kernel_registry.hpp>

#include <oscar/idl_texts.hpp>

namespace oscar::modules {

void Logger::Params::describe(ParamSpec& spec) {
  spec.field("file", file, "the MCAP file to write (created on the first cue)").fixed();
  spec.field("inputs", inputs, "inputs to declare: 'name:Type, ...' (Bool, LineSeg3DSeq, GvImage)")
      .fixed();
  spec.field("compression", compression, "chunk compression")
      .one_of({"zstd", "lz4", "none"})
      .fixed();
  spec.field("flush_every", flush_every, "write the open chunk when its oldest cue is this old");
}

struct Logger::Port {
  virtual ~Port() = default;
  /// Every new cue: (serialised bytes, header, receive time).
  struct Item {
    std::vector<std::uint8_t> bytes;
    const CueHeader* header;
    Stamp received;
    std::shared_ptr<const void> keep;
  };
  virtual std::vector<Item> take() = 0;
  virtual const std::string& type() const = 0;
};

namespace {
template <class T>
struct TypedPort final : Logger::Port {
  TypedPort(KernelSetup& setup, const std::string& name)
      : in(setup.input<T>(name, {.depth = 256, .transfer = Transfer::kPush})) {}
  std::vector<Item> take() override {
    std::vector<Item> out;
    for (auto& r : in.take_new()) {
      out.push_back(
          {cue_type_info<T>().serialize(r.cue.get()), &r.cue->header(), r.received, r.cue});
    }
    return out;
  }
  const std::string& type() const override { return cue_type_info<T>().name; }
  Input<T>& in;
};
}  // namespace

std::vector<Logger::InputSpec> Logger::parse_inputs(const std::string& text) {
  static const std::regex entry(
      R"(\s*([A-Za-z_][A-Za-z0-9_]*)\s*:\s*([A-Za-z_][A-Za-z0-9_:]*)\s*)");
  std::vector<InputSpec> out;
  std::set<std::string> names;
  std::size_t start = 0;
  while (start <= text.size()) {
    const auto comma = text.find(',', start);
    const auto item =
        text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    std::smatch m;
    if (!std::regex_match(item, m, entry)) {
      throw std::invalid_argument("logger: parameter 'inputs': '" + item +
                                  "' is not 'name:Type' (e.g. 'cam:GvImage, flag:Bool')");
    }
    if (!names.insert(m[1]).second) {
      throw std::invalid_argument("logger: parameter 'inputs': input '" + m[1].str() +
                                  "' is declared twice");
    }
    out.push_back({m[1], m[2]});
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
  if (params_.inputs.empty()) {
    throw std::invalid_argument(
        "logger: parameter 'inputs' must declare at least one input, e.g. 'cam:GvImage'");
  }
  for (const auto& spec : parse_inputs(params_.inputs)) {
    ports_.push_back(visit_standard_type(spec.type, [&]<class T>() -> std::unique_ptr<Port> {
      return std::make_unique<TypedPort<T>>(setup, spec.name);
    }));
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

std::uint16_t Logger::channel(const std::string& source, const std::string& type) {
  // The topic the cue travels on: oscar/cue/<kernel>/<channel> (from its header's source).
  const auto topic = "oscar/cue/" + source;
  if (auto it = channels_.find(topic); it != channels_.end()) return it->second;
  std::uint16_t schema = 0;
  if (auto s = schemas_.find(type); s != schemas_.end()) {
    schema = s->second;
  } else if (auto idl = idl_texts().find(type); idl != idl_texts().end()) {
    schema = schemas_[type] =
        writer_->add_schema(type, "omgidl", {idl->second.begin(), idl->second.end()});
  }
  std::map<std::string, std::string> meta{{"type", type}, {"logger", "true"}};
  const auto slash = source.find('/');
  meta["kernel"] = source.substr(0, slash);
  if (slash != std::string::npos) meta["channel"] = source.substr(slash + 1);
  return channels_[topic] = writer_->add_channel(schema, topic, "cdr", meta);
}

void Logger::process(Cycle& cycle) {
  // This cycle's cues of all inputs in the order they arrived: the file is in log-time order.
  std::vector<std::pair<Port::Item, const Port*>> items;
  for (auto& port : ports_) {
    for (auto& item : port->take()) items.emplace_back(std::move(item), port.get());
  }
  std::stable_sort(items.begin(), items.end(), [](const auto& a, const auto& b) {
    return a.first.received < b.first.received;
  });
  for (const auto& [item, port] : items) {
    if (!writer_) open();
    mcap::MessageView m;
    m.channel_id = channel(item.header->source(), port->type());
    m.sequence = static_cast<std::uint32_t>(item.header->seq());
    m.log_time = static_cast<std::uint64_t>(item.received);
    m.publish_time = item.header->stamps().empty() ? m.log_time : item.header->stamps()[0];
    m.data = item.bytes;
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
