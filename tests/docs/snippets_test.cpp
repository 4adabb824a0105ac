// Docs stay true: every code block in docs/, README.md and modules/*/README.md marked `<!--
// snippet: PATH -->` must appear verbatim in PATH (documentation code is cut from
// compiled files).
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include "source_tree.hpp"

namespace {
namespace fs = std::filesystem;

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(DocSnippets, EveryMarkedCodeBlockMatchesItsSource) {
  const fs::path root = oscar::testing::source_path();
  std::vector<fs::path> docs{root / "README.md"};
  for (const auto& e : fs::directory_iterator(root / "docs")) {
    if (e.path().extension() == ".md") docs.push_back(e.path());
  }
  for (const auto& e : fs::directory_iterator(root / "modules")) {
    if (fs::exists(e.path() / "README.md")) docs.push_back(e.path() / "README.md");
  }
  int checked = 0;
  const std::string marker = "<!-- snippet: ";
  for (const auto& doc : docs) {
    const auto text = read(doc);
    for (auto at = text.find(marker); at != std::string::npos; at = text.find(marker, at + 1)) {
      const auto path_end = text.find(" -->", at);
      const auto source = root / text.substr(at + marker.size(), path_end - at - marker.size());
      const auto open = text.find("```", path_end);
      const auto body = text.find('\n', open) + 1;
      const auto close = text.find("```", body);
      const auto block = text.substr(body, close - body);
      ASSERT_TRUE(fs::exists(source)) << doc << ": snippet source " << source << " is missing";
      EXPECT_NE(read(source).find(block), std::string::npos)
          << doc << ": this block is no longer in " << source << ":\n"
          << block;
      ++checked;
    }
  }
  EXPECT_GT(checked, 0) << "no snippets found: the marker changed?";
}

}  // namespace
