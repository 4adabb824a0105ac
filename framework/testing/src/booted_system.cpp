#include "oscar/testing/booted_system.hpp"

#include <fcntl.h>
#include <linux/close_range.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>
#include <charconv>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "oscar/config_client.hpp"
#include "oscar/cue_type_info.hpp"
#include "oscar/cue_types.hpp"
#include "oscar/malformed_samples.hpp"
#include "oscar/module_spec.hpp"
#include "oscar/process_util.hpp"
#include "oscar/registry/registry_client.hpp"
#include "oscar/registry/running_systems.hpp"
#include "oscar/registry/system_spec.hpp"
#include "oscar/security_files.hpp"
#include "oscar/shared_memory.hpp"
#include "oscar/test_domain.hpp"
#include "oscar/testing/eventually.hpp"

namespace oscar::testing {
namespace {
namespace fs = std::filesystem;
using namespace std::chrono_literals;

// Fast DDS computes its ports as 7400 + 250 * domain + ...: 232 is the last domain that fits.
constexpr int kLastDomain = 232;

// Where FreeDomain keeps its locks: $OSCAR_TEST_DOMAINS_DIR, else /tmp/oscar/test-domains.
std::string domain_locks() {
  const char* env = std::getenv("OSCAR_TEST_DOMAINS_DIR");
  return env && *env ? env : "/tmp/oscar/test-domains";
}
const fs::path kShm = "/dev/shm";

// Whether a /dev/shm file is one of `domain`'s Fast DDS ports (fastrtps_port<N>, its lock
// "_el" and its semaphore "sem.fastrtps_port<N>_mutex", N in 7400 + 250 * domain + [0, 250)).
bool is_port_of_domain(const std::string& name, int domain) {
  constexpr std::string_view kPort = "fastrtps_port";
  const auto at = name.find(kPort);
  if (at != 0 && !(at == 4 && name.starts_with("sem."))) return false;
  int port = 0;
  const auto* first = name.data() + at + kPort.size();
  const auto [end, error] = std::from_chars(first, name.data() + name.size(), port);
  if (error != std::errc() || end == first) return false;
  const int base = 7400 + 250 * domain;
  return port >= base && port < base + 250;
}

// `program` from $OSCAR_BIN_DIR, else from PATH.
std::string find_program(const std::string& program) {
  if (const char* dir = std::getenv("OSCAR_BIN_DIR"); dir && *dir) {
    const auto path = fs::path(dir) / program;
    if (access(path.c_str(), X_OK) == 0) return path.string();
    throw std::runtime_error(fmt::format(
        "oscar::testing: {} is not in $OSCAR_BIN_DIR ({}), which must be OSCAR's bin folder",
        program, dir));
  }
  if (const char* path = std::getenv("PATH")) {
    std::stringstream dirs(path);
    for (std::string dir; std::getline(dirs, dir, ':');) {
      const auto candidate = fs::path(dir.empty() ? "." : dir) / program;
      if (access(candidate.c_str(), X_OK) == 0) return candidate.string();
    }
  }
  throw std::runtime_error(
      fmt::format("oscar::testing: cannot find {}: set $OSCAR_BIN_DIR to OSCAR's bin folder "
                  "(oscar_add_system_test does) or put that folder on PATH",
                  program));
}

std::vector<std::string> command_line(pid_t pid) {
  std::ifstream in(fmt::format("/proc/{}/cmdline", pid));
  std::vector<std::string> args;
  for (std::string arg; std::getline(in, arg, '\0');) args.push_back(arg);
  return args;
}

// The processes boot started for this system: the registry, the monitors and the modules all
// get the system file and the domain on their command line.
std::vector<pid_t> processes_of(const std::string& file, int domain) {
  std::vector<pid_t> out;
  const auto dom = std::to_string(domain);
  std::error_code ec;
  for (const auto& e : fs::directory_iterator("/proc", ec)) {
    const auto name = e.path().filename().string();
    if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos) continue;
    const auto args = command_line(std::stoi(name));
    const bool has_file = std::find(args.begin(), args.end(), file) != args.end();
    const auto d = std::find(args.begin(), args.end(), "--domain");
    if (has_file && d != args.end() && d + 1 != args.end() && *(d + 1) == dom)
      out.push_back(std::stoi(name));
  }
  return out;
}

// The /dev/shm files a process owns: Fast DDS holds the lock file "<name>_el" of each of its
// segments and ports open for as long as it lives, and OSCAR its participant id claims. With
// each lock go the segment or port itself and, for a port, the semaphore it is opened under.
void add_shared_memory_of(pid_t pid, std::set<std::string>& files) {
  std::error_code ec;
  for (const auto& fd : fs::directory_iterator(fmt::format("/proc/{}/fd", pid), ec)) {
    std::error_code ignore;
    const auto target = fs::read_symlink(fd.path(), ignore);
    if (ignore || target.parent_path() != kShm) continue;
    const auto name = target.filename().string();
    files.insert(name);
    if (name.starts_with("fastrtps_") && name.ends_with("_el")) {
      const auto owned = name.substr(0, name.size() - 3);
      files.insert(owned);
      if (owned.starts_with("fastrtps_port")) files.insert("sem." + owned + "_mutex");
    }
  }
}

// True if nobody holds the lock of `path` (its owner is gone).
bool abandoned(const fs::path& path) {
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool free = flock(fd, LOCK_EX | LOCK_NB) == 0;
  close(fd);
  return free;
}

std::string tail(const std::string& text, std::size_t lines) {
  std::size_t pos = text.size();
  for (std::size_t n = 0; n <= lines && pos != std::string::npos && pos > 0; ++n)
    pos = text.rfind('\n', pos - 1);
  return pos == std::string::npos || pos == 0 ? text : text.substr(pos + 1);
}

// Counts the cues of one channel whatever their type (a registered cue type, named by
// discovery).
class CueCounter final : public eprosima::fastdds::dds::DataReaderListener {
 public:
  CueCounter(DdsParticipant& p, const std::string& topic, const CueTypeInfo& type)
      : participant_(p), type_(type) {
    reader_ = p.subscriber().create_datareader(
        &p.topic(topic, type.new_topic_type()),
        qos::cue_reader(OutputOptions{.reliable = false}, 16, Reliability::kBestEffort), this);
    if (!reader_) throw std::runtime_error("cannot create a reader for " + topic);
  }
  ~CueCounter() override { participant_.subscriber().delete_datareader(reader_); }
  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override {
    const auto cue = type_.make();
    eprosima::fastdds::dds::SampleInfo info;
    while (take_next(*reader, cue.get(), info) == ReturnCode_t::RETCODE_OK) {
      if (info.valid_data) ++count_;
    }
  }
  std::size_t count() const { return count_; }

 private:
  DdsParticipant& participant_;
  const CueTypeInfo& type_;
  eprosima::fastdds::dds::DataReader* reader_ = nullptr;
  std::atomic<std::size_t> count_{0};
};

}  // namespace

FreeDomain::FreeDomain(int first) {
  if (first < 1 || first > kLastDomain) {
    throw std::invalid_argument(
        fmt::format("oscar::testing::FreeDomain({}): a domain is 1 to {}", first, kLastDomain));
  }
  const auto locks = domain_locks();
  std::error_code ec;
  fs::create_directories(locks, ec);
  fs::permissions(locks, fs::perms::all, ec);  // every user's tests share it
  std::set<int> booted;
  for (const auto& s : running_systems()) booted.insert(s.domain);
  // From the top down by default: systems and tools use low domains (0 when told nothing, the
  // examples 42 to 44).
  for (int i = 0; i < kLastDomain; ++i) {
    const int domain = (first - 1 - i + kLastDomain) % kLastDomain + 1;  // first, down, wrapping
    if (booted.count(domain)) continue;
    const auto path = fmt::format("{}/domain-{}.lock", locks, domain);
    const int fd = open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
    if (fd < 0) continue;
    if (flock(fd, LOCK_EX | LOCK_NB) == 0) {
      domain_ = domain;
      fd_ = fd;
      return;
    }
    close(fd);
  }
  throw std::runtime_error(fmt::format(
      "oscar::testing: every DDS domain from 1 to {} is taken, by systems booted on this "
      "machine or by other tests (their locks are in {})",
      kLastDomain, locks));
}

FreeDomain::~FreeDomain() {
  if (fd_ >= 0) close(fd_);  // the lock file stays: removing it could race another's lock
}

SystemUnderTest::SystemUnderTest(const std::string& system_file, BootOptions options) {
  if (!fs::is_regular_file(system_file)) {
    throw std::invalid_argument(
        fmt::format("oscar::testing: the system file '{}' does not exist", system_file));
  }
  const auto boot = find_program("oscar-boot");
  file_ = fs::absolute(system_file).lexically_normal().string();
  if (options.domain < 0) {
    free_domain_ = std::make_unique<FreeDomain>();
    domain_ = free_domain_->domain();
  } else {
    domain_ = options.domain;
  }
  std::string work = (fs::temp_directory_path() / "oscar-test-XXXXXX").string();
  if (!mkdtemp(work.data()))
    throw std::runtime_error("oscar::testing: cannot make a temporary folder in " + work);
  work_dir_ = work;
  log_dir_ = options.log_dir.empty() ? work_dir_ + "/logs" : options.log_dir;
  boot_log_ = work_dir_ + "/boot.log";

  // Ports a killed earlier run left in this domain would be opened by this system's processes,
  // taken for its own and left behind at shutdown (no one else uses the domain: FreeDomain).
  DeadSharedMemorySweeper(std::chrono::seconds(0), kShm, [&](const std::string& name) {
    return is_port_of_domain(name, domain_);
  }).sweep();
  register_standard_cue_types();
  // The network profile of the system's local host (its interfaces, peers or discovery servers)
  // with boot's authority; a keystore given to this test wins over the file's.
  const auto system = SystemSpec::load(file_);
  auto network = system.network_for(system.local_host().name, security_files::kOperatorBoot);
  const auto keystore =
      options.keystore.empty() ? std::string{} : fs::absolute(options.keystore).string();
  if (!keystore.empty()) {
    network.security = ParticipantSecurity{keystore, security_files::kOperatorBoot};
  }
  participant_ = std::make_unique<DdsParticipant>(domain_, "oscar-test", network);
  registry_ = std::make_unique<RegistryClient>(*participant_, "test");
  config_ = std::make_unique<ConfigClient>(*participant_, "boot");

  std::vector<std::string> argv{
      boot,        file_,    "--domain",  std::to_string(domain_),
      "--log-dir", log_dir_, "--timeout", std::to_string(options.boot_timeout.count())};
  if (!options.keystore.empty()) argv.insert(argv.end(), {"--keystore", keystore});
  std::vector<char*> args;
  for (auto& a : argv) args.push_back(a.data());
  args.push_back(nullptr);
  const pid_t parent = getpid();
  boot_pid_ = fork();
  if (boot_pid_ < 0) throw std::runtime_error("oscar::testing: cannot fork to start oscar-boot");
  if (boot_pid_ == 0) {
    // Its own process group, to be killed as one; and a test process that dies (a crash, the
    // ctest timeout) makes boot shut its system down as Ctrl-C would.
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(127);
    const int fd = ::open(boot_log_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd >= 0) {
      dup2(fd, 1);
      dup2(fd, 2);
    }
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    // The test's own DDS sockets and shared-memory locks stay with the test.
    close_range(3, ~0U, CLOSE_RANGE_CLOEXEC);
    execv(args[0], args.data());
    _exit(127);
  }
  setpgid(boot_pid_, boot_pid_);  // also here: whichever of the two runs first
}

SystemUnderTest::~SystemUnderTest() {
  shut_down();
  std::error_code ec;
  if (::testing::Test::HasFailure()) {
    std::fprintf(stderr, "oscar::testing: the system's output is kept in %s\n", work_dir_.c_str());
  } else {
    fs::remove_all(work_dir_, ec);
  }
}

std::string SystemUnderTest::boot_output() const {
  std::ifstream in(boot_log_);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::optional<int> SystemUnderTest::boot_exit_code(std::chrono::milliseconds timeout) {
  eventually(
      [&] {
        if (boot_status_) return true;
        int status = 0;
        if (waitpid(boot_pid_, &status, WNOHANG) == boot_pid_) {
          boot_status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        }
        return boot_status_.has_value();
      },
      timeout, 10ms);
  return boot_status_;
}

std::string SystemUnderTest::report() const {
  const auto last = registry_->latest();
  std::string modules;
  if (last) {
    for (const auto& m : last->modules()) {
      modules += fmt::format("\n  {} {}{}", m.name(), m.status(),
                             m.last_failure().empty() ? "" : " (" + m.last_failure() + ")");
    }
  }
  return fmt::format(
      "system on domain {}: {}{}\nboot's output ({}):\n{}", domain_,
      last ? last->state() + (last->message().empty() ? "" : " (" + last->message() + ")")
           : std::string("no state from its registry"),
      modules, boot_log_, tail(boot_output(), 30));
}

void SystemUnderTest::note_processes() {
  std::set<pid_t> pids(pids_.begin(), pids_.end());
  if (!boot_status_) pids.insert(boot_pid_);
  for (const pid_t p : processes_of(file_, domain_)) pids.insert(p);
  if (const auto last = registry_ ? registry_->latest() : std::nullopt) {
    for (const auto& m : last->modules()) {
      if (m.pid() > 0) pids.insert(static_cast<pid_t>(m.pid()));
    }
  }
  std::set<std::string> files(shm_files_.begin(), shm_files_.end());
  for (const pid_t p : pids) {
    if (p == boot_pid_ || process_lives(p)) add_shared_memory_of(p, files);
  }
  pids_.assign(pids.begin(), pids.end());
  shm_files_.assign(files.begin(), files.end());
}

std::optional<SystemState> SystemUnderTest::wait_for(
    const std::function<bool(const SystemState&)>& pred, std::chrono::milliseconds timeout) {
  auto state = registry_->wait_for(pred, timeout);
  note_processes();
  return state;
}

::testing::AssertionResult SystemUnderTest::wait_until_running(
    const std::vector<std::string>& modules, std::chrono::milliseconds timeout) {
  const auto all_run = [&](const SystemState& s) {
    if (s.state() != "running") return false;
    for (const auto& name : modules) {
      const auto m = std::find_if(s.modules().begin(), s.modules().end(),
                                  [&](const ModuleEntry& e) { return e.name() == name; });
      if (m == s.modules().end() || m->status() != "running") return false;
    }
    return true;
  };
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < until) {
    if (wait_for(all_run, 200ms)) return ::testing::AssertionSuccess();
    if (boot_exit_code()) break;  // boot gave up (or refused the file): no use waiting
  }
  return ::testing::AssertionFailure()
         << fmt::format("not every module of {} ran within {} ms", fmt::join(modules, ", "),
                        timeout.count())
         << (boot_status_ ? fmt::format("; oscar boot exited with code {}", *boot_status_) : "")
         << "\n"
         << report();
}

::testing::AssertionResult SystemUnderTest::wait_for_cues(const std::vector<std::string>& channels,
                                                          std::size_t count,
                                                          std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  const auto left = [&] {
    return std::chrono::duration_cast<std::chrono::milliseconds>(until -
                                                                 std::chrono::steady_clock::now());
  };
  std::vector<std::unique_ptr<CueCounter>> counters;
  for (const auto& channel : channels) {
    const auto topic = topics::cue(channel);
    std::optional<DdsParticipant::DiscoveredWriter> writer;
    eventually([&] { return (writer = participant_->discovered_writer(topic)).has_value(); },
               left(), 10ms);
    if (!writer) {
      return ::testing::AssertionFailure() << "nothing publishes " << channel << " (topic " << topic
                                           << ") within " << timeout.count() << " ms\n"
                                           << report();
    }
    const auto* type = find_cue_type(writer->type);
    if (!type) {
      return ::testing::AssertionFailure()
             << channel << " carries cues of type " << writer->type
             << ", which this test does not know: read them with watch<T>() or read_cues<T>()";
    }
    counters.push_back(std::make_unique<CueCounter>(*participant_, topic, *type));
  }
  for (std::size_t i = 0; i < channels.size(); ++i) {
    if (!eventually([&] { return counters[i]->count() >= count; }, left(), 10ms)) {
      return ::testing::AssertionFailure()
             << channels[i] << " carried " << counters[i]->count() << " of " << count
             << " cues within " << timeout.count() << " ms\n"
             << report();
    }
  }
  note_processes();
  return ::testing::AssertionSuccess();
}

ConfigReply SystemUnderTest::configure(const std::string& module, CommandKind kind,
                                       std::vector<std::string> args,
                                       std::chrono::milliseconds timeout) {
  return config_->send(module, kind, std::move(args), timeout);
}

std::optional<int> SystemUnderTest::shut_down(std::chrono::milliseconds timeout) {
  if (shut_down_) return *shut_down_;
  note_processes();
  if (!boot_exit_code()) {
    kill(boot_pid_, SIGINT);  // as Ctrl-C: boot stops the modules in order, then the rest
    if (!boot_exit_code(timeout)) {
      killpg(boot_pid_, SIGKILL);  // what boot started dies with it (PR_SET_PDEATHSIG)
      boot_exit_code(5s);
    }
  }
  const bool killed = !boot_status_ || *boot_status_ == 128 + SIGKILL;
  // Whatever outlived boot (a process it started that ignored it) is killed, by pid: only
  // processes with this system's file and domain on their command line.
  note_processes();
  for (const pid_t p : processes_of(file_, domain_)) kill(p, SIGKILL);
  eventually([&] { return leftover_processes().empty(); }, 10s, 10ms);
  config_.reset();
  registry_.reset();
  watches_->close_all();  // the test's watches read through the participant
  participant_.reset();
  // Fast DDS leaves the semaphores of its ports (and a killed process everything): remove the
  // files of the system's processes, now that none of them lives.
  const std::set<std::string> mine(shm_files_.begin(), shm_files_.end());
  DeadSharedMemorySweeper(std::chrono::seconds(0), kShm, [&](const std::string& name) {
    return mine.count(name) > 0;
  }).sweep();
  std::error_code ec;
  for (const auto& name : shm_files_) {
    if (name.starts_with("oscar_participant_") && abandoned(kShm / name))
      fs::remove(kShm / name, ec);
  }
  shut_down_.emplace(killed ? std::nullopt : boot_status_);
  return *shut_down_;
}

std::vector<pid_t> SystemUnderTest::leftover_processes() const {
  std::set<pid_t> left;
  for (const pid_t p : pids_) {
    if (p != boot_pid_ && process_lives(p)) left.insert(p);
  }
  for (const pid_t p : processes_of(file_, domain_)) left.insert(p);
  if (!boot_status_ && process_lives(boot_pid_)) left.insert(boot_pid_);
  return {left.begin(), left.end()};
}

std::vector<std::string> SystemUnderTest::leftover_shared_memory() const {
  std::vector<std::string> left;
  for (const auto& name : shm_files_) {
    std::error_code ec;
    if (fs::exists(kShm / name, ec)) left.push_back(name);
  }
  return left;
}

SystemUnderTest& BootedSystem::boot(const std::string& system_file, BootOptions options) {
  auto file = system_file;
  if (file.empty()) {
    const char* env = std::getenv("OSCAR_TEST_SYSTEM");
    if (!env || !*env) {
      throw std::invalid_argument(
          "oscar::testing::BootedSystem::boot(): no system file given and $OSCAR_TEST_SYSTEM is "
          "not set (oscar_add_system_test sets it to its SYSTEM file)");
    }
    file = env;
  }
  system_.reset();
  system_ = std::make_unique<SystemUnderTest>(file, std::move(options));
  return *system_;
}

SystemUnderTest& BootedSystem::system() {
  if (!system_) throw std::logic_error("oscar::testing::BootedSystem: call boot() first");
  return *system_;
}

void BootedSystem::TearDown() {
  if (!system_) return;
  const auto code = system_->shut_down();
  EXPECT_TRUE(code.has_value()) << "oscar boot did not stop within 40 s and was killed";
  EXPECT_EQ(system_->leftover_processes(), std::vector<pid_t>{})
      << "processes of the system outlived its shutdown";
  EXPECT_EQ(system_->leftover_shared_memory(), std::vector<std::string>{})
      << "shared-memory files of the system outlived its shutdown";
  system_.reset();
}

void use_programs_beside_this_one() {
  if (const char* dir = std::getenv("OSCAR_BIN_DIR"); dir && *dir) return;
  std::error_code ec;
  const auto self = fs::read_symlink("/proc/self/exe", ec);
  if (!ec && fs::exists(self.parent_path() / "oscar-boot")) {
    setenv("OSCAR_BIN_DIR", self.parent_path().c_str(), 1);
  }
}

}  // namespace oscar::testing

namespace oscar {

int process_test_domain(int first) {
  static const testing::FreeDomain domain(first);
  return domain.domain();
}

}  // namespace oscar
