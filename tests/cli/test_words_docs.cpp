// README.md and docs/*.md name only what is in the repository (issue 24,
// item 8): every path under a top-level folder of the repository
// (`src/...`, `robots/*_friction.yaml`, ...) exists or, as a pattern,
// matches a file, nothing is named outside the repository (the project's
// shared folder, `../`), and every Markdown file named (`DESIGN.md`) is one of the
// repository's. Paths under build/ are build outputs and not checked; names
// without a folder (`model.yaml`, `traj.csv`) are placeholders.
#include <fnmatch.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
const fs::path kRoot = LCSIM_SOURCE_DIR;

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The repository's files relative to its root, without build trees and .git.
std::vector<std::string> repository_files() {
  std::vector<std::string> out;
  for (auto it = fs::recursive_directory_iterator(kRoot); it != fs::recursive_directory_iterator();
       ++it) {
    const std::string name = it->path().filename().string();
    if (it->is_directory() && (name == ".git" || name.rfind("build", 0) == 0)) {
      it.disable_recursion_pending();
      continue;
    }
    if (it->is_regular_file()) out.push_back(fs::relative(it->path(), kRoot).string());
  }
  return out;
}

// A file or folder, or a pattern of one: `*` and a placeholder such as
// `<name>` stand for any part of a name (`robots/*_friction.yaml`,
// `src/cli/cmd_<name>.cpp`, `fuzz/corpus/<target>`).
bool named_thing_exists(const std::string& path, const std::vector<std::string>& files) {
  const std::string pattern = std::regex_replace(path, std::regex("<[^>/]*>"), "*");
  if (pattern.find('*') == std::string::npos) return fs::exists(kRoot / path);
  for (const auto& f : files)  // the file or a folder above it
    for (fs::path p = f; !p.empty(); p = p.parent_path())
      if (::fnmatch(pattern.c_str(), p.c_str(), FNM_PATHNAME) == 0) return true;
  return false;
}

TEST(WordsDocs, ReadmeAndDocsNameOnlyWhatIsInTheRepository) {
  const std::vector<std::string> files = repository_files();
  std::set<std::string> md_names;
  for (const auto& f : files)
    if (fs::path(f).extension() == ".md") md_names.insert(fs::path(f).filename().string());
  std::vector<fs::path> docs{kRoot / "README.md"};
  for (const auto& e : fs::directory_iterator(kRoot / "docs"))
    if (e.path().extension() == ".md") docs.push_back(e.path());
  ASSERT_GE(docs.size(), 5u);  // README and the docs/ pages: the scan found them
  const std::regex path(
      R"((?:^|[^\w./-])((?:src|include|tests|python|docs|robots|examples|bench|scripts|fuzz|cmake|status|\.ci)/[\w./*+<>-]*[\w*>]))");
  const std::regex md(R"((?:^|[^\w./-])([\w-]+\.md)\b)");
  // Outside the repository: up and out of it, or the project's shared folder.
  const std::regex outside(R"((?:^|[^\w./-])((?:\.\./)*shared/[\w./-]+|/work/[\w./-]+))");
  int checked = 0;
  for (const auto& doc : docs) {
    const std::string text = read(doc);
    for (std::sregex_iterator m(text.begin(), text.end(), path), end; m != end; ++m, ++checked)
      EXPECT_TRUE(named_thing_exists((*m)[1], files))
          << doc.filename() << " names " << (*m)[1] << ", which is not in the repository";
    for (std::sregex_iterator m(text.begin(), text.end(), md), end; m != end; ++m, ++checked)
      EXPECT_TRUE(md_names.count((*m)[1]))
          << doc.filename() << " names " << (*m)[1] << ", which is not in the repository";
    for (std::sregex_iterator m(text.begin(), text.end(), outside), end; m != end; ++m)
      ADD_FAILURE() << doc.filename() << " names " << (*m)[1]
                    << ", which is outside the repository";
  }
  EXPECT_GE(checked, 50);  // the patterns do match the pages' paths
}

}  // namespace
