#include "oscar/registry/system_spec.hpp"

#include <unistd.h>

#include <filesystem>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "oscar/cue_types.hpp"
#include "oscar/kernel_registry.hpp"

namespace oscar {
namespace {

using ::testing::HasSubstr;

SystemSpec parse(const std::string& yaml) { return SystemSpec::parse(YAML::Load(yaml), "s.yaml"); }

std::string error_of(const std::string& yaml) {
  try {
    parse(yaml);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no error";
}

constexpr const char* kTwoHosts = R"(
system: t
domain: 7
hosts: { a: { local: true, address: 10.77.0.1 }, b: { netns: hb, address: 10.77.0.2 } }
modules:
  - name: src
    host: a
    kernels: [ { type: bench_source, name: src } ]
    mode: { continuous: 50ms }
    restart: { policy: auto, max: 2, window: 30s, backoff: 100ms, on_limit: continue }
  - name: sink
    host: b
    kernels: [ { type: bench_sink, name: sink, inputs: { in: src/out } } ]
    restart: { replace: spare }
  - name: spare
    host: b
    standby: true
    kernels: [ { type: bench_sink, name: spare_sink, inputs: { in: src/out } } ]
)";

TEST(SystemSpec, ReadsHostsPoliciesAndPerHostNetworks) {
  const auto s = parse(kTwoHosts);
  EXPECT_EQ(s.name, "t");
  EXPECT_EQ(s.domain, 7);
  ASSERT_EQ(s.hosts.size(), 2u);
  EXPECT_EQ(s.host("b").kind, HostSpec::Kind::kNetns);
  EXPECT_EQ(s.local_host().name, "a");
  const auto* src = s.find_module("src");
  ASSERT_NE(src, nullptr);
  EXPECT_EQ(src->restart.max, 2);
  EXPECT_EQ(src->restart.window, std::chrono::seconds(30));
  EXPECT_EQ(src->restart.backoff, std::chrono::milliseconds(100));
  EXPECT_TRUE(src->restart.continue_on_limit);
  EXPECT_EQ(s.find_module("sink")->restart.window, std::chrono::minutes(10)) << "the default";
  EXPECT_EQ(src->spec.domain, 7);
  EXPECT_EQ(src->spec.network.interfaces, std::vector<std::string>{"10.77.0.1"});
  EXPECT_EQ(src->spec.network.peers, (std::vector<std::string>{"10.77.0.1", "10.77.0.2"}));
  EXPECT_EQ(s.find_module("sink")->restart.kind, RestartPolicy::Kind::kReplace);
  EXPECT_TRUE(s.find_module("spare")->standby);
}

TEST(SystemSpec, WithoutHostsEverythingRunsOnOneLocalHostOnLoopback) {
  const auto s = parse("modules: [ { name: m, kernels: [ { type: relay } ] } ]");
  ASSERT_EQ(s.hosts.size(), 1u);
  EXPECT_EQ(s.modules[0].spec.host, "localhost");
  EXPECT_EQ(s.modules[0].spec.network.interfaces, std::vector<std::string>{"127.0.0.1"});
}

TEST(SystemSpec, MalformedYamlNamesFileLineAndColumn) {
  const auto path = ::testing::TempDir() + "/malformed.yaml";
  std::FILE* f = std::fopen(path.c_str(), "w");
  std::fputs("system: x\nmodules:\n  - name: [unclosed\n", f);
  std::fclose(f);
  try {
    SystemSpec::load(path);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr(path + ":4:"));
    EXPECT_THAT(e.what(), HasSubstr("malformed YAML"));
  }
}

TEST(SystemSpec, UnknownKeysAreErrorsWithTheirLine) {
  EXPECT_THAT(error_of("system: x\nmodulez: []\n"),
              HasSubstr("s.yaml:2: system file: unknown key 'modulez'"));
  EXPECT_THAT(
      error_of("modules: [ { name: m, kernels: [ {type: relay} ], restart: { polcy: auto } } ]"),
      HasSubstr("unknown key 'polcy'"));
}

constexpr const char* kOneModule = "modules: [ { name: m, kernels: [ {type: relay} ] } ]\n";

TEST(SystemSpec, HeadlessLimitIsADurationOrNone) {
  EXPECT_EQ(parse(kOneModule).headless_limit, std::chrono::milliseconds(2000)) << "the default";
  EXPECT_EQ(parse(std::string("headless_limit: 5s\n") + kOneModule).headless_limit,
            std::chrono::milliseconds(5000));
  EXPECT_EQ(parse(std::string("headless_limit: none\n") + kOneModule).headless_limit, std::nullopt);
  EXPECT_THAT(error_of(std::string("headless_limit: 0s\n") + kOneModule),
              HasSubstr("headless_limit (or none): must be positive"));
  EXPECT_THAT(error_of(std::string("headless_limit: forever\n") + kOneModule),
              HasSubstr("headless_limit (or none)"));
}

TEST(SystemSpec, OnLostIsSuspendOrContinuePerHost) {
  const auto plain = parse(kTwoHosts);
  EXPECT_FALSE(plain.hosts[1].continue_when_lost) << "the default: the system waits for the host";
  auto yaml = std::string(kTwoHosts);
  const std::string b = "b: { netns: hb, address: 10.77.0.2 }";
  yaml.replace(yaml.find(b), b.size(), "b: { netns: hb, address: 10.77.0.2, on_lost: continue }");
  const auto going_on = parse(yaml);
  EXPECT_FALSE(going_on.hosts[0].continue_when_lost);
  EXPECT_TRUE(going_on.hosts[1].continue_when_lost);
  yaml.replace(yaml.find("continue }"), 8, "suspend");
  EXPECT_FALSE(parse(yaml).hosts[1].continue_when_lost);
  yaml.replace(yaml.find("suspend }"), 7, "resume");
  EXPECT_THAT(error_of(yaml), HasSubstr("hosts.b.on_lost 'resume': expected suspend (the system "
                                        "waits for the host) or continue"));
}

TEST(SystemSpec, SecuritySectionIsOptionalAndReadsKeystoreAndCueProtection) {
  EXPECT_FALSE(parse(kOneModule).security);
  const auto s =
      SystemSpec::parse(YAML::Load(std::string(kOneModule) +
                                   "security: { keystore: keys, cue_protection: encrypt }\n"),
                        "/robots/alpha/s.yaml");
  ASSERT_TRUE(s.security);
  EXPECT_EQ(s.security->keystore, "/robots/alpha/keys");  // relative to the system file
  EXPECT_EQ(s.security->cue_protection, SecuritySpec::CueProtection::kEncrypt);
  const auto plain = parse(std::string(kOneModule) + "security: { keystore: /etc/oscar/keys }\n");
  EXPECT_EQ(plain.security->keystore, "/etc/oscar/keys");
  EXPECT_EQ(plain.security->cue_protection, SecuritySpec::CueProtection::kNone);
}

TEST(SystemSpec, SecuritySectionRefusesUnknownKeysAndProtections) {
  EXPECT_THAT(error_of(std::string(kOneModule) + "security: { keystore: k, cue: sign }\n"),
              HasSubstr("s.yaml:2: security: unknown key 'cue' (allowed: keystore, "
                        "cue_protection)"));
  EXPECT_THAT(error_of(std::string(kOneModule) + "security: { cue_protection: secret }\n"),
              HasSubstr("s.yaml:2: security.cue_protection 'secret': expected none, sign or "
                        "encrypt"));
  EXPECT_THAT(error_of(std::string(kOneModule) + "security: yes\n"),
              HasSubstr("s.yaml:2: security: expected {keystore: DIR"));
}

TEST(SystemSpec, ADiscoveryServerWithAKeystoreIsRefusedNamingTheRule) {
  EXPECT_THAT(error_of(std::string(kOneModule) +
                       "security: { keystore: /etc/oscar/keys }\nnetwork: { discovery: server }\n"),
              HasSubstr("s.yaml:3: network.discovery: server cannot run with DDS Security "
                        "(keystore /etc/oscar/keys): Fast DDS 2.9 has no authenticated discovery "
                        "server; use discovery: static"));
  EXPECT_NO_THROW(parse(std::string(kOneModule) + "network: { discovery: server }\n"));
  EXPECT_NO_THROW(parse(std::string(kOneModule) + "security: { keystore: /etc/oscar/keys }\n"));
}

TEST(SystemSpec, UnknownHostIsAnErrorListingTheHosts) {
  EXPECT_THAT(error_of(R"(
hosts: { a: { local: true } }
modules: [ { name: m, host: z, kernels: [ { type: relay } ] } ])"),
              HasSubstr("module 'm': unknown host 'z' (hosts: a)"));
}

TEST(SystemSpec, DuplicateModuleAndKernelNamesAreErrors) {
  EXPECT_THAT(error_of(R"(modules:
  - { name: m, kernels: [ { type: relay, name: a } ] }
  - { name: m, kernels: [ { type: relay, name: b } ] })"),
              HasSubstr("duplicate module name 'm'"));
  EXPECT_THAT(error_of(R"(modules:
  - { name: m, kernels: [ { type: relay, name: a } ] }
  - { name: n, kernels: [ { type: relay, name: a } ] })"),
              HasSubstr("duplicate kernel name 'a' (also in module 'm')"));
}

TEST(SystemSpec, WiringToAnUnknownKernelIsAnError) {
  EXPECT_THAT(
      error_of("modules: [ { name: m, kernels: [ { type: relay, inputs: { in: ghost/out } } ] } ]"),
      HasSubstr("kernel 'relay' input 'in': no kernel 'ghost' in the system"));
}

TEST(SystemSpec, CyclicReplaceChainsAreErrorsShowingTheChain) {
  EXPECT_THAT(error_of(R"(modules:
  - { name: a, kernels: [ { type: relay, name: ka } ], restart: { replace: b } }
  - { name: b, standby: true, kernels: [ { type: relay, name: kb } ], restart: { replace: c } }
  - { name: c, standby: true, kernels: [ { type: relay, name: kc } ], restart: { replace: b } })"),
              HasSubstr("cyclic replace chain: a -> b -> c -> b"));
}

TEST(SystemSpec, AReplacementMustExistAndBeStandby) {
  EXPECT_THAT(
      error_of("modules: [ { name: a, kernels: [ { type: relay } ], restart: { replace: z } } ]"),
      HasSubstr("module 'a': replace names no module 'z'"));
  EXPECT_THAT(error_of(R"(modules:
  - { name: a, kernels: [ { type: relay, name: ka } ], restart: { replace: b } }
  - { name: b, kernels: [ { type: relay, name: kb } ] })"),
              HasSubstr("its replacement 'b' must be declared standby: true"));
}

TEST(SystemSpec, BadPolicyValuesAreErrors) {
  EXPECT_THAT(
      error_of(
          "modules: [ { name: a, kernels: [ { type: relay } ], restart: { policy: often } } ]"),
      HasSubstr("restart.policy 'often': expected auto, manual or replace"));
  EXPECT_THAT(
      error_of(
          "modules: [ { name: a, kernels: [ { type: relay } ], restart: { backoff: soon } } ]"),
      HasSubstr("restart.backoff"));
  EXPECT_THAT(
      error_of("modules: [ { name: a, kernels: [ { type: relay } ], restart: { window: 0s } } ]"),
      HasSubstr("module 'a'.restart.window: must be positive"));
  EXPECT_THAT(
      error_of("modules: [ { name: a, kernels: [ { type: relay } ], debug: { gdbserver: 0 } } ]"),
      HasSubstr("gdbserver: a TCP port"));
  EXPECT_THAT(error_of("hosts: { a: { local: true, netns: x } }\nmodules: []"),
              HasSubstr("give exactly one of local, netns, ssh"));
  EXPECT_THAT(error_of("hosts: { a: { ssh: 'u@h; rm -rf /' } }\nmodules: []"),
              HasSubstr("without shell characters"));
}

TEST(SystemSpec, AnSshHostNeedsAnAddressAndTakesSshOptions) {
  EXPECT_THAT(error_of("hosts: { a: { local: true }, b: { ssh: u@b } }\nmodules: []"),
              HasSubstr("hosts.b: an ssh host needs address:"));
  EXPECT_THAT(error_of("hosts: { b: { ssh: u@b, address: 10.77.0.2, ssh_options: [Port 22] } }\n"
                       "modules: []"),
              HasSubstr("hosts.b.ssh_options 'Port 22': expected Key=Value"));
  EXPECT_THAT(error_of("hosts: { b: { netns: b, ssh_options: [Port=22] } }\nmodules: []"),
              HasSubstr("hosts.b: ssh_options go with ssh"));
  const auto s = parse(
      "hosts: { a: { local: true }, b: { ssh: u@b, address: 10.77.0.2, ssh_options: [Port=2222, "
      "IdentityFile=~/.ssh/robot] } }\nmodules: [ { name: m, host: b, kernels: [ { type: relay } "
      "] } ]");
  EXPECT_EQ(s.host("b").ssh_options,
            (std::vector<std::string>{"Port=2222", "IdentityFile=~/.ssh/robot"}));
}

TEST(SystemSpec, CheckModulesRejectsAnUnknownKernelType) {
  register_standard_cue_types();
  const auto s = parse("modules: [ { name: m, kernels: [ { type: no_such_kernel, name: k } ] } ]");
  try {
    s.check_modules(plugin_search_path());
    FAIL() << "no error";
  } catch (const std::exception& e) {
    EXPECT_THAT(e.what(), HasSubstr("no_such_kernel"));
  }
}

// A plugin outside every default folder, named by the system file (relative to its folder) as a
// folder or as a file: boot --check and oscar-run (Module) find it with no OSCAR_PLUGIN_PATH.
TEST(SystemSpec, PluginsNamedByTheSystemFileAreFoundRelativeToIt) {
  register_standard_cue_types();
  std::string relay;
  for (const auto& dir : plugin_search_path()) {
    if (std::filesystem::exists(dir + "/liboscar_kernel_relay.so")) relay = dir;
  }
  ASSERT_FALSE(relay.empty()) << "the build's relay plugin";
  const auto dir =
      std::filesystem::temp_directory_path() / ("oscar_plugins_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir / "mine");
  std::filesystem::copy_file(relay + "/liboscar_kernel_relay.so",
                             dir / "mine" / "liboscar_kernel_relay.so");
  for (const auto* plugins : {"mine", "[mine/liboscar_kernel_relay.so]"}) {
    const auto s = SystemSpec::parse(
        YAML::Load(std::string("plugins: ") + plugins +
                   "\nmodules: [ { name: m, kernels: [ { type: relay, name: r, params: { type: "
                   "Bool } } ] } ]"),
        (dir / "system.yaml").string());
    EXPECT_EQ(s.modules[0].spec.plugins.front().rfind((dir / "mine").string(), 0), 0u) << plugins;
    EXPECT_NO_THROW(s.check_modules({})) << "only the file's plugins: to search";
  }
  std::filesystem::remove_all(dir);
}

TEST(SystemSpec, APluginPathThatDoesNotExistIsAnErrorWithItsLine) {
  EXPECT_THAT(
      error_of("system: t\nplugins: [nowhere]\nmodules: [ { name: m, kernels: [ { type: "
               "relay, name: r } ] } ]"),
      testing::AllOf(HasSubstr("s.yaml:2: plugins: '"), HasSubstr("/nowhere' does not exist")));
}

TEST(SystemSpec, CheckModulesRefusesAReliableInputReadingABestEffortOutputOfAnotherModule) {
  register_standard_cue_types();
  const auto s = parse(R"(
modules:
  - { name: a, kernels: [ { type: test_emitter, name: src, params: { reliable: false } } ] }
  - name: b
    kernels: [ { type: test_reliable_collect, name: sink, inputs: { in: src/out } } ]
)");
  try {
    s.check_modules(plugin_search_path());
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("s.yaml:5: input 'sink.in' (reliable) is wired to 'src/out', "
                                    "which is best effort"));
  }
}

TEST(SystemSpec, ZeroCopyIsOffByDefaultAndTakesTrueFalseOrAChunkCount) {
  constexpr const char* kModules = "modules: [ { name: m, kernels: [ { type: relay } ] } ]\n";
  EXPECT_FALSE(parse(kModules).zero_copy);
  EXPECT_FALSE(parse(std::string(kModules) + "zero_copy: false\n").zero_copy);
  const auto on = parse(std::string(kModules) + "zero_copy: true\n").zero_copy;
  ASSERT_TRUE(on);
  EXPECT_EQ(on->chunks, 64u);
  EXPECT_EQ(on->where, "s.yaml:2");
  const auto sized = parse(std::string(kModules) + "zero_copy: { chunks: 100 }\n").zero_copy;
  ASSERT_TRUE(sized);
  EXPECT_EQ(sized->chunks, 100u);
  const std::string form =
      "zero_copy: expected true, false or {chunks: N} (N chunks of each plain cue type, 1..4096)";
  EXPECT_EQ(error_of(std::string(kModules) + "zero_copy: yes please\n"), "s.yaml:2: " + form);
  EXPECT_EQ(error_of(std::string(kModules) + "zero_copy: { chunks: 0 }\n"), "s.yaml:2: " + form);
  EXPECT_EQ(error_of(std::string(kModules) + "zero_copy: { chunks: many }\n"), "s.yaml:2: " + form);
  EXPECT_EQ(error_of(std::string(kModules) + "zero_copy: [1]\n"), "s.yaml:2: " + form);
  EXPECT_THAT(error_of(std::string(kModules) + "zero_copy: { chunk: 8 }\n"), HasSubstr("chunk"));
}

}  // namespace
}  // namespace oscar
