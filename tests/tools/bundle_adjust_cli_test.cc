// `reconar bundle-adjust` as a user meets it: the JSON summary on the BAL Ladybug problem, and
// clear errors (naming the file, exit code 2) for a missing and a truncated BAL file.
//
// The dataset's SOURCE.txt records no reference cost, so the solve is checked on structural
// facts (counts, finite costs, a convergence termination) and a cost decrease of at least 10x.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include "core/base/atomic_file.h"
#include "tests/support/run_command.h"

namespace {

namespace fs = std::filesystem;

const std::string kLadybug = std::string(RECONAR_SHARED_DATA_DIR) + "/bal_ladybug/problem-49-7776-pre.txt";

fs::path TempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("reconar_ba_cli_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

using reconar::testing::CommandRun;

CommandRun RunReconar(const std::string& arguments) {
  return reconar::testing::RunReconar(arguments, reconar::testing::StderrMode::kSeparate);
}

// A flat JSON object whose values are strings, numbers or null (what bundle-adjust prints).
// Values are kept as text: strings unescaped, numbers and null verbatim. False on any syntax
// error, duplicate key or trailing text.
bool ParseFlatJsonObject(const std::string& text, std::map<std::string, std::string>* object) {
  size_t i = 0;
  auto skip_space = [&] {
    while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
  };
  auto parse_string = [&](std::string* out) {
    if (i >= text.size() || text[i] != '"') return false;
    for (++i; i < text.size() && text[i] != '"'; ++i) {
      if (text[i] == '\\') {
        if (++i >= text.size()) return false;
        if (text[i] != '"' && text[i] != '\\' && text[i] != '/') return false;  // enough for our output
      }
      *out += text[i];
    }
    if (i >= text.size()) return false;
    ++i;
    return true;
  };
  skip_space();
  if (i >= text.size() || text[i++] != '{') return false;
  skip_space();
  if (i < text.size() && text[i] == '}') {
    ++i;
  } else {
    for (;;) {
      std::string key, value;
      skip_space();
      if (!parse_string(&key)) return false;
      skip_space();
      if (i >= text.size() || text[i++] != ':') return false;
      skip_space();
      if (i < text.size() && text[i] == '"') {
        if (!parse_string(&value)) return false;
      } else if (text.compare(i, 4, "null") == 0) {
        value = "null";
        i += 4;
      } else {
        char* end = nullptr;
        std::strtod(text.c_str() + i, &end);
        if (end == text.c_str() + i) return false;
        value = text.substr(i, static_cast<size_t>(end - (text.c_str() + i)));
        i = static_cast<size_t>(end - text.c_str());
      }
      if (!object->emplace(key, value).second) return false;
      skip_space();
      if (i >= text.size()) return false;
      if (text[i] == '}') {
        ++i;
        break;
      }
      if (text[i++] != ',') return false;
    }
  }
  skip_space();
  return i == text.size();
}

double Number(const std::map<std::string, std::string>& object, const std::string& key) {
  auto it = object.find(key);
  if (it == object.end()) return std::nan("");
  char* end = nullptr;
  const double value = std::strtod(it->second.c_str(), &end);
  return *end == '\0' ? value : std::nan("");
}

TEST(BundleAdjustCli, LadybugJsonSummary) {
  const CommandRun run = RunReconar("bundle-adjust --bal " + kLadybug + " --json --threads 2");
  ASSERT_EQ(run.exit_code, 0) << run.output << run.error;
  std::map<std::string, std::string> json;
  ASSERT_TRUE(ParseFlatJsonObject(run.output, &json)) << "not exactly one JSON object:\n" << run.output;
  for (const char* key : {"file", "cameras", "points", "observations", "initial_cost", "final_cost", "iterations",
                          "seconds", "termination"}) {
    EXPECT_EQ(json.count(key), 1u) << key;
  }
  EXPECT_EQ(json.size(), 9u);
  EXPECT_EQ(json["file"], kLadybug);
  // Counts from the dataset's SOURCE.txt.
  EXPECT_EQ(Number(json, "cameras"), 49);
  EXPECT_EQ(Number(json, "points"), 7776);
  EXPECT_EQ(Number(json, "observations"), 31843);
  const double initial = Number(json, "initial_cost"), final = Number(json, "final_cost");
  ASSERT_TRUE(std::isfinite(initial) && std::isfinite(final)) << run.output;
  EXPECT_GT(final, 0.0);
  EXPECT_LT(final, initial);
  EXPECT_LE(10.0 * final, initial) << "expected at least a 10x decrease";
  const double iterations = Number(json, "iterations");
  EXPECT_GE(iterations, 1);
  EXPECT_LE(iterations, 100);  // default --max-iterations
  EXPECT_GE(Number(json, "seconds"), 0.0);
  const std::string& termination = json["termination"];
  EXPECT_TRUE(termination.find("tolerance") != std::string::npos) << "not converged: " << termination;
}

TEST(BundleAdjustCli, HumanReadableSummaryAndOptions) {
  const CommandRun run =
      RunReconar("bundle-adjust --bal " + kLadybug + " --solver sparse --loss huber --loss-scale 2 --max-iterations 3");
  ASSERT_EQ(run.exit_code, 0) << run.output << run.error;
  EXPECT_NE(run.output.find("49 cameras, 7776 points, 31843 observations"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("in 3 iterations"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("sparse solver"), std::string::npos) << run.output;
}

TEST(BundleAdjustCli, UsageErrors) {
  EXPECT_EQ(RunReconar("bundle-adjust --help").exit_code, 0);
  EXPECT_EQ(RunReconar("bundle-adjust").exit_code, 2);
  const CommandRun bad_solver = RunReconar("bundle-adjust --bal " + kLadybug + " --solver qr");
  EXPECT_EQ(bad_solver.exit_code, 2);
  EXPECT_NE(bad_solver.error.find("--solver"), std::string::npos) << bad_solver.error;
  const CommandRun bad_loss = RunReconar("bundle-adjust --bal " + kLadybug + " --loss tukey");
  EXPECT_EQ(bad_loss.exit_code, 2);
  EXPECT_NE(bad_loss.error.find("--loss"), std::string::npos) << bad_loss.error;
}

TEST(BundleAdjustCli, MissingFileIsNamed) {
  const std::string missing = "/nonexistent/problem.txt";
  const CommandRun run = RunReconar("bundle-adjust --bal " + missing + " --json");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_TRUE(run.output.empty()) << run.output;
  EXPECT_NE(run.error.find(missing), std::string::npos) << run.error;
}

TEST(BundleAdjustCli, TruncatedFileIsNamed) {
  auto bytes = reconar::ReadFileToString(kLadybug);
  ASSERT_TRUE(bytes.ok()) << bytes.status().ToString();
  const fs::path truncated = TempDir("truncated") / "problem-truncated.txt";
  std::ofstream(truncated, std::ios::binary) << bytes->substr(0, bytes->size() / 2);
  const CommandRun run = RunReconar("bundle-adjust --bal " + truncated.string() + " --json");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_TRUE(run.output.empty()) << run.output;
  EXPECT_NE(run.error.find(truncated.string()), std::string::npos) << run.error;
}

}  // namespace
