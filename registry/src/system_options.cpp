#include "oscar/registry/system_options.hpp"

#include "oscar/network.hpp"
#include "oscar/registry/registry_client.hpp"
#include "oscar/registry/system_spec.hpp"

namespace oscar {

namespace {
void add_domain(CLI::App& app, int& domain, const char* help) {
  app.add_option("-d,--domain", domain, help)->check(CLI::Range(0, 232));
}
}  // namespace

void SystemOptions::add_to(CLI::App& app) {
  app.add_option("--system", system_file, "system file (its domain and network)");
  app.add_option("--host", host, "the host this runs on (with --system)");
  add_domain(app, domain,
             "DDS domain (default: the system file's, $OSCAR_DOMAIN, the system booted on this "
             "machine, or 0)");
}

void SystemOptions::add_domain_to(CLI::App& app) {
  add_domain(app, domain,
             "DDS domain (default: $OSCAR_DOMAIN, the system booted on this machine, or 0)");
}

std::unique_ptr<DdsParticipant> SystemOptions::participant(const std::string& name,
                                                           ToolAuthority authority) const {
  return tool_participant(name, system_file, host, domain, authority);
}

int SystemOptions::resolved_domain() const {
  if (domain >= 0) return domain;
  if (!system_file.empty()) return SystemSpec::load(system_file).domain;
  if (const int from_env = domain_from_env(-1); from_env >= 0) return from_env;
  const auto booted = default_system();
  return booted ? booted->domain : 0;
}

}  // namespace oscar
