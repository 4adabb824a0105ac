// `oscar`: the command line front end. `oscar <cmd> args...` runs the program `oscar-<cmd>`
// found beside this one (then on PATH), `oscar bench <what> args...` runs `oscar-bench-<what>`:
// each tool links only what it needs, and new tools need no change here (like git).
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

namespace {

const char* const kUsage =
    "usage: oscar <command> [args...]\n"
    "\n"
    "commands (each is the program oscar-<command>):\n"
    "  boot SYSTEM.yaml      boot a system across hosts; follow its log until Ctrl-C\n"
    "  ps                    the running system's modules: host, pid, state, restarts, rates\n"
    "  restart MODULE        restart a module (also one given up or on manual policy)\n"
    "  shutdown              stop the running system in order\n"
    "  log                   follow the merged log of the running system\n"
    "  run ...               host kernels in one module process (oscar-run)\n"
    "  config MODULE CMD ... send a configuration command to a module\n"
    "  applets run FILE      run an applet-scheduler scenario (also: applets ps, graph,\n"
    "                        add FILE, remove --applet NAME | --service NAME)\n"
    "  swarm plan FILE       plan jobs and trajectories for a swarm\n"
    "  record [TOPIC...]     record cue topics to an MCAP file\n"
    "  info FILE             summarise an MCAP file\n"
    "  replay FILE           republish a recording with its original timing\n"
    "  topics                topics of the running system with types, QoS and rates\n"
    "  echo TOPIC            print a topic's samples readably (headers, fields)\n"
    "  hz TOPIC              a topic's rate and the min/max/std of its period\n"
    "  graph [-o FILE.svg]   the running system as a graph (modules, kernels, channels)\n"
    "  bridge foxglove       serve the running system live to Foxglove (ws://127.0.0.1:8765)\n"
    "  new-module NAME ...   generate a module: kernel, CMake, README, unit test\n"
    "  security init|check|list SYSTEM.yaml\n"
    "                        the system's DDS Security keystore (--keystore DIR)\n"
    "  bench <what> ...      benchmarks: cueflow, restart, boot, applets, swarm, record,\n"
    "                        replay, landmarks, bridge, stalls, discovery, pull\n"
    "\n"
    "`oscar <command> --help` shows a command's options.\n";

std::filesystem::path own_dir() {
  std::error_code ec;
  auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::filesystem::path() : exe.parent_path();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0) {
    std::fputs(kUsage, argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  std::string program = std::string("oscar-") + argv[1];
  int first_arg = 2;
  if (program == "oscar-bench") {
    if (argc < 3) {
      std::fputs(
          "usage: oscar bench "
          "<cueflow|restart|boot|applets|swarm|record|replay|landmarks|bridge|stalls|discovery|"
          "pull> "
          "[args...]\n",
          stderr);
      return 2;
    }
    program += std::string("-") + argv[2];
    first_arg = 3;
  }
  std::vector<char*> args{program.data()};
  for (int i = first_arg; i < argc; ++i) args.push_back(argv[i]);
  args.push_back(nullptr);

  const auto beside = own_dir() / program;
  if (std::filesystem::exists(beside)) {
    execv(beside.c_str(), args.data());
  } else {
    execvp(program.c_str(), args.data());
  }
  if (errno == ENOENT) {
    std::fprintf(stderr, "oscar: unknown command '%s' (no program %s beside %s or on PATH)\n\n%s",
                 program.c_str() + 6, program.c_str(), own_dir().c_str(), kUsage);
    return 2;
  }
  std::fprintf(stderr, "oscar: cannot run %s: %s\n", program.c_str(), std::strerror(errno));
  return 2;
}
