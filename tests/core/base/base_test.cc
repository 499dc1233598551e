#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <filesystem>
#include <numeric>
#include <vector>

#include "core/base/arena.h"
#include "core/base/json_writer.h"
#include "core/base/keep_masked.h"
#include "core/base/atomic_file.h"
#include "core/base/image.h"
#include "core/base/progress.h"
#include "core/base/status.h"
#include "core/base/thread_pool.h"
#include "core/base/union_find.h"

namespace reconar {
namespace {

namespace fs = std::filesystem;

fs::path TempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("reconar_base_" + std::to_string(::getpid())) / name;
  fs::create_directories(dir);
  return dir;
}

Result<int> ParsePositive(int v) {
  if (v <= 0) return InvalidArgument("value " + std::to_string(v) + " is not positive");
  return v;
}

Status Twice(int v, int* out) {
  RECONAR_ASSIGN_OR_RETURN(const int parsed, ParsePositive(v));
  *out = 2 * parsed;
  return Status::Ok();
}

TEST(Status, CarriesCodeMessageAndContext) {
  EXPECT_TRUE(Status::Ok().ok());
  const Status s = FileError(StatusCode::kCorruptData, "a.jpg", "truncated");
  EXPECT_FALSE(s.ok());
  EXPECT_EQ(s.code(), StatusCode::kCorruptData);
  EXPECT_EQ(s.message(), "a.jpg: truncated");
  EXPECT_EQ(s.WithContext("features").message(), "features: a.jpg: truncated");
  int out = 0;
  EXPECT_TRUE(Twice(4, &out).ok());
  EXPECT_EQ(out, 8);
  const Status bad = Twice(-1, &out);
  EXPECT_EQ(bad.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(out, 8);
}

TEST(Arena, AlignsCountsAndResetsWithScope) {
  Arena arena(1024);
  void* a = arena.Allocate(10, 64);
  ASSERT_NE(a, nullptr);
  EXPECT_EQ(reinterpret_cast<uintptr_t>(a) % 64, 0u);
  {
    Arena::Scope scope(arena);
    void* b = arena.Allocate(100, 64);
    ASSERT_NE(b, nullptr);
    EXPECT_EQ(reinterpret_cast<uintptr_t>(b) % 64, 0u);
    EXPECT_EQ(arena.used(), 64u + 100u);
    EXPECT_EQ(arena.wasted(), 54u);
  }
  EXPECT_EQ(arena.used(), 10u);
  EXPECT_EQ(arena.peak_used(), 164u);
}

TEST(Arena, RefusesWhatDoesNotFitAndStaysUsable) {
  Arena arena(256);
  EXPECT_EQ(arena.Allocate(300), nullptr);
  EXPECT_EQ(arena.failed_allocations(), 1u);
  EXPECT_EQ(arena.used(), 0u);
  EXPECT_NE(arena.Allocate(200), nullptr);
  EXPECT_EQ(arena.Allocate(100), nullptr);
  EXPECT_EQ(arena.failed_allocations(), 2u);
  arena.Reset();
  EXPECT_NE(arena.AllocateArray<double>(32), nullptr);
  Arena huge(size_t{8} << 20);  // takes the huge-page path
  EXPECT_NE(huge.Allocate(size_t{8} << 20), nullptr);
}

TEST(ImageView, StridedSubViewsAddressTheParent) {
  Image<uint8_t> image(6, 4);
  std::iota(image.data(), image.data() + 24, 0);
  ImageView<uint8_t> view = image.view();
  ImageView<const uint8_t> sub = view.sub(2, 1, 3, 2);
  EXPECT_EQ(sub.width, 3);
  EXPECT_EQ(sub.stride, 6);
  EXPECT_EQ(sub.at(0, 0), 8);
  EXPECT_EQ(sub.at(2, 1), 16);
  Image<uint8_t> rgb(2, 2, 3);
  EXPECT_EQ(rgb.view().width, 6);
  EXPECT_EQ(rgb.size_bytes(), 12u);
}

TEST(ThreadPool, VisitsEveryIndexOnceWithValidWorkerIds) {
  for (int threads : {1, 2, 4}) {
    ThreadPool pool(threads);
    EXPECT_EQ(pool.num_threads(), threads);
    for (int round = 0; round < 3; ++round) {
      std::vector<std::atomic<int>> visits(1000);
      std::atomic<int> bad_worker{0};
      pool.ParallelFor(0, visits.size(), [&](size_t i, int worker) {
        visits[i]++;
        if (worker < 0 || worker >= threads) bad_worker++;
      });
      for (auto& v : visits) ASSERT_EQ(v.load(), 1);
      EXPECT_EQ(bad_worker.load(), 0);
    }
    pool.ParallelFor(5, 5, [](size_t, int) { FAIL(); });
  }
}

TEST(Progress, PlainLinesWhenNotATerminal) {
  const fs::path path = TempDir("progress") / "log.txt";
  std::FILE* file = std::fopen(path.c_str(), "w+");
  ASSERT_NE(file, nullptr);
  {
    Progress progress("features", 20, file);
    EXPECT_FALSE(progress.is_terminal());
    for (int i = 0; i < 20; ++i) progress.Advance();
  }
  std::fclose(file);
  auto text = ReadFileToString(path.string());
  ASSERT_TRUE(text.ok());
  EXPECT_NE(text->find("features: 10/20 (50%)"), std::string::npos) << *text;
  EXPECT_NE(text->find("features: 20/20 (100%)"), std::string::npos) << *text;
  EXPECT_LE(std::count(text->begin(), text->end(), '\n'), 12);
}

TEST(AtomicFile, WritesReplacesAndCleansUp) {
  const fs::path dir = TempDir("atomic");
  const std::string path = (dir / "out.txt").string();
  ASSERT_TRUE(WriteFileAtomically(path, std::string("first")).ok());
  ASSERT_TRUE(WriteFileAtomically(path, std::string("second")).ok());
  EXPECT_EQ(*ReadFileToString(path), "second");
  // A failing writer leaves the old content and no temporary behind.
  const Status failed = WriteFileAtomically(path, [](std::FILE* f) {
    std::fputs("partial", f);
    return IoError("writer gave up");
  });
  EXPECT_FALSE(failed.ok());
  EXPECT_EQ(*ReadFileToString(path), "second");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
  const Status missing_dir = WriteFileAtomically((dir / "no" / "such" / "x").string(), std::string("x"));
  EXPECT_EQ(missing_dir.code(), StatusCode::kIoError);
  EXPECT_NE(missing_dir.message().find("no/such/x"), std::string::npos);
  EXPECT_EQ(ReadFileToString((dir / "absent").string()).status().code(), StatusCode::kNotFound);
}

// A full disk, simulated with a file-size limit: the write fails with a message naming the file,
// the previous version survives and no half file is left.
// What a SIGKILL during a write leaves: the temporary of a process that is gone is removed, a
// live process's (this one's) and files that only look similar are kept.
TEST(AtomicFile, StaleTemporariesOfDeadProcessesAreRemoved) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("reconar_stale_tmp_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir / "sub");
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ASSERT_GT(child, 0);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);  // reaped: its pid names no process now
  const std::string dead = std::to_string(child), alive = std::to_string(::getpid());
  const std::vector<std::string> names = {"sub/points.ply.tmp-" + dead, "a.txt.tmp-" + alive, "b.tmp-x", "c.tmp-"};
  for (const std::string& name : names) {
    ASSERT_TRUE(WriteFileAtomically((dir / name).string(), "x").ok());
  }
  auto removed = RemoveStaleTemporaryFiles(dir.string());
  ASSERT_TRUE(removed.ok()) << removed.status().ToString();
  EXPECT_EQ(*removed, 1);
  EXPECT_FALSE(std::filesystem::exists(dir / ("sub/points.ply.tmp-" + dead)));
  EXPECT_TRUE(std::filesystem::exists(dir / ("a.txt.tmp-" + alive)));
  EXPECT_TRUE(std::filesystem::exists(dir / "b.tmp-x"));
  EXPECT_TRUE(std::filesystem::exists(dir / "c.tmp-"));
  EXPECT_EQ(*RemoveStaleTemporaryFiles((dir / "missing").string()), 0);
  std::filesystem::remove_all(dir);
}

TEST(AtomicFile, FullDiskLeavesNoHalfFile) {
  const fs::path dir = TempDir("full");
  const std::string path = (dir / "model.ply").string();
  ASSERT_TRUE(WriteFileAtomically(path, std::string("old")).ok());
  struct sigaction ignore {}, previous {};
  ignore.sa_handler = SIG_IGN;
  sigaction(SIGXFSZ, &ignore, &previous);
  rlimit old_limit{};
  getrlimit(RLIMIT_FSIZE, &old_limit);
  rlimit small = old_limit;
  small.rlim_cur = 4096;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
  const Status status = WriteFileAtomically(path, std::string(1 << 20, 'x'));
  setrlimit(RLIMIT_FSIZE, &old_limit);
  sigaction(SIGXFSZ, &previous, nullptr);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.code(), StatusCode::kIoError);
  EXPECT_NE(status.message().find(path), std::string::npos) << status.message();
  EXPECT_EQ(*ReadFileToString(path), "old");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
}

}  // namespace
}  // namespace reconar

namespace reconar {
namespace {

TEST(JsonWriter, WritesNestedValuesWithEscapesAndRoundTripDoubles) {
  JsonWriter json;
  json.BeginObject()
      .Key("name").String("a \"b\"\n\\")
      .Key("n").Int(-3)
      .Key("x").Double(0.1)
      .Key("y").Double(1.0 / 3.0)
      .Key("bad").Double(std::numeric_limits<double>::quiet_NaN())
      .Key("list").BeginArray().Bool(true).Null().BeginObject().EndObject().EndArray()
      .EndObject();
  EXPECT_EQ(json.str(),
            "{\"name\":\"a \\\"b\\\"\\n\\\\\",\"n\":-3,\"x\":0.1,\"y\":0.3333333333333333,"
            "\"bad\":null,\"list\":[true,null,{}]}");
  EXPECT_EQ(std::strtod("0.3333333333333333", nullptr), 1.0 / 3.0);
  EXPECT_EQ(JsonQuote(std::string("\x01", 1)), "\"\\u0001\"");
}

TEST(JsonWriter, PrettyPrintsWithIndent) {
  JsonWriter json(2);
  json.BeginObject().Key("a").Int(1).Key("b").BeginArray().Int(2).EndArray().EndObject();
  EXPECT_EQ(json.str(), "{\n  \"a\": 1,\n  \"b\": [\n    2\n  ]\n}");
}

TEST(JsonWriter, RawValuesAreInsertedAsTheyAre) {
  JsonWriter json;
  json.BeginObject().Key("a").Raw("{\"b\": [1, 2]}\n").Key("c").BeginArray().Raw("3").Raw("4").EndArray().EndObject();
  EXPECT_EQ(json.str(), "{\"a\":{\"b\": [1, 2]},\"c\":[3,4]}");
}

TEST(KeepMasked, KeepsMarkedValuesInOrderAndLeavesEmptyAttributes) {
  const std::vector<uint8_t> keep = {1, 0, 0, 1, 1};
  std::vector<int> values = {10, 11, 12, 13, 14};
  KeepMasked(keep, &values);
  EXPECT_EQ(values, (std::vector<int>{10, 13, 14}));
  std::vector<float> absent;
  KeepMasked(keep, &absent);
  EXPECT_TRUE(absent.empty());
}

TEST(UnionFind, RootIsTheSmallestMemberWhateverTheOrder) {
  UnionFind sets(6);
  sets.Union(5, 3);
  sets.Union(3, 4);
  sets.Union(1, 2);
  EXPECT_EQ(sets.Find(4), 3u);
  EXPECT_EQ(sets.Find(5), 3u);
  EXPECT_EQ(sets.Find(2), 1u);
  EXPECT_EQ(sets.Find(0), 0u);
  sets.Union(4, 2);
  for (uint32_t x : {1u, 2u, 3u, 4u, 5u}) EXPECT_EQ(sets.Find(x), 1u);
}

}  // namespace
}  // namespace reconar
