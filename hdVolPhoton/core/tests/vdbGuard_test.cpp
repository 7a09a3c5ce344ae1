// The VDB reader guard (core/vdbGuard.h): the real probe passes sound files and files that fail
// cleanly; stand-in probes (shell scripts named by HDVOLPHOTON_VDBPROBE) that die by a signal, hang
// or cannot start show how each ending is reported, that verdicts are cached per file and that the
// host never stops.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <mutex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/diagnostics.h"
#include "core/gridMedium.h"
#include "core/proceduralCloud.h"
#include "core/vdbGuard.h"

using namespace volphoton;

namespace {

/// A fresh folder per test (ctest runs tests in parallel processes).
std::string testDir() {
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) /
                                ("volphoton_vdbguard_" + std::string(info->name()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir.string();
}

void writeFile(const std::string& path, const std::string& bytes) {
    std::ofstream out(path, std::ios::binary);
    out << bytes;
}

std::string readFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

size_t countLines(const std::string& path) {
    std::string text = readFile(path);
    return size_t(std::count(text.begin(), text.end(), '\n'));
}

/// An executable shell script standing in for the probe; it appends its arguments to `log`.
std::string stubProbe(const std::string& dir, const std::string& name, const std::string& body) {
    std::string path = dir + "/" + name;
    writeFile(path, "#!/bin/sh\necho \"$@\" >> '" + dir + "/" + name + ".log'\n" + body + "\n");
    ::chmod(path.c_str(), 0755);
    return path;
}

/// Sets HDVOLPHOTON_VDBPROBE (or unsets it for ""), clears the verdict cache, and captures the
/// diagnostics while alive; restores all three afterwards.
struct GuardFixture {
    explicit GuardFixture(const std::string& probe) {
        if (probe.empty()) ::unsetenv("HDVOLPHOTON_VDBPROBE");
        else ::setenv("HDVOLPHOTON_VDBPROBE", probe.c_str(), 1);
        clearVdbCrashCheckCache();
        setDiagnosticSink([this](Severity, const std::string& m) {
            std::lock_guard<std::mutex> lock(mutex);
            messages.push_back(m);
        });
    }
    ~GuardFixture() {
        setDiagnosticSink({});
        ::unsetenv("HDVOLPHOTON_VDBPROBE");
        clearVdbCrashCheckCache();
    }
    void setProbe(const std::string& probe) { ::setenv("HDVOLPHOTON_VDBPROBE", probe.c_str(), 1); }
    std::mutex mutex;
    std::vector<std::string> messages;
};

}  // namespace

TEST(VdbGuard, TheBundledProbeIsFoundBesideTheModule) {
    GuardFixture guard("");
    std::string probe = vdbProbePath();
    ASSERT_FALSE(probe.empty()) << "volphoton-vdbprobe is not beside the test executable";
    EXPECT_EQ(std::filesystem::path(probe).filename(), "volphoton-vdbprobe");
    std::string dir = testDir();
    guard.setProbe(dir + "/elsewhere");
    EXPECT_EQ(vdbProbePath(), dir + "/elsewhere") << "the environment variable overrides the bundled probe";
}

TEST(VdbGuard, SoundFilesAndCleanFailuresPassTheRealProbe) {
    GuardFixture guard("");
    std::string dir = testDir();
    std::string good = dir + "/good.vdb";
    writeProceduralCloudVdb(good, 16, 0.1, 1);
    std::string bytes = readFile(good);
    std::string truncated = dir + "/truncated.vdb";
    writeFile(truncated, bytes.substr(0, 200));
    EXPECT_EQ(vdbCrashCheck(good, "density"), std::nullopt);
    EXPECT_EQ(vdbCrashCheck(truncated, "density"), std::nullopt) << "a clean error is the real load's to report";
    EXPECT_EQ(vdbCrashCheck(good, "no_such_grid"), std::nullopt);
    EXPECT_EQ(vdbCrashCheck(dir + "/missing.vdb", "density"), std::nullopt);
    EXPECT_TRUE(guard.messages.empty()) << guard.messages.front();
}

TEST(VdbGuard, AProbeKilledByASignalNamesTheSignalAndIsCachedPerFile) {
    std::string dir = testDir();
    GuardFixture guard(stubProbe(dir, "segv", "kill -SEGV $$"));
    std::string file = dir + "/x.vdb";
    writeFile(file, "not a vdb");
    std::optional<std::string> problem = vdbCrashCheck(file, "density");
    ASSERT_TRUE(problem.has_value());
    EXPECT_NE(problem->find("crashed"), std::string::npos) << *problem;
    EXPECT_NE(problem->find("SIGSEGV"), std::string::npos) << *problem;
    EXPECT_EQ(countLines(dir + "/segv.log"), 1u);

    // Cached: the same answer without running a probe again (even one that would pass).
    guard.setProbe(stubProbe(dir, "ok", "exit 0"));
    EXPECT_EQ(vdbCrashCheck(file, "density"), problem);
    EXPECT_EQ(countLines(dir + "/segv.log"), 1u);
    EXPECT_FALSE(std::filesystem::exists(dir + "/ok.log"));

    // Another grid of the file, or the file rewritten (another size), is probed anew.
    EXPECT_EQ(vdbCrashCheck(file, "smoke"), std::nullopt);
    writeFile(file, "not a vdb, longer");
    EXPECT_EQ(vdbCrashCheck(file, "density"), std::nullopt);
    EXPECT_EQ(countLines(dir + "/ok.log"), 2u);
}

TEST(VdbGuard, AHangingProbeIsKilledAtTheTimeOut) {
    std::string dir = testDir();
    GuardFixture guard(stubProbe(dir, "hang", "exec sleep 30"));
    std::string file = dir + "/slow.vdb";
    writeFile(file, "x");
    auto start = std::chrono::steady_clock::now();
    std::optional<std::string> problem = vdbCrashCheck(file, "density", 0.3);
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_TRUE(problem.has_value());
    EXPECT_NE(problem->find("longer than 0.3 s"), std::string::npos) << *problem;
    EXPECT_GE(seconds, 0.3);
    EXPECT_LT(seconds, 5.0) << "the probe must be killed at the deadline, not waited for";
}

TEST(VdbGuard, AProbeThatCannotRunWarnsOnceAndLetsTheLoadGoOn) {
    std::string dir = testDir();
    GuardFixture guard(dir + "/no_probe_here");
    std::string file = dir + "/a.vdb";
    writeFile(file, "x");
    EXPECT_EQ(vdbCrashCheck(file, "density"), std::nullopt);
    EXPECT_EQ(vdbCrashCheck(file, "density"), std::nullopt);
    ASSERT_EQ(guard.messages.size(), 1u) << "one warning, not one per file or per check";
    EXPECT_NE(guard.messages[0].find("no_probe_here"), std::string::npos) << guard.messages[0];
    EXPECT_NE(guard.messages[0].find("without the guard"), std::string::npos) << guard.messages[0];

    // A probe that ends with an error status says nothing about the file: a warning, not a verdict,
    // and not cached (the crashing probe that follows is run).
    guard.setProbe(stubProbe(dir, "broken", "exit 3"));
    EXPECT_EQ(vdbCrashCheck(file, "density"), std::nullopt);
    ASSERT_EQ(guard.messages.size(), 2u);
    EXPECT_NE(guard.messages[1].find("exit status 3"), std::string::npos) << guard.messages[1];
    guard.setProbe(stubProbe(dir, "abort", "kill -ABRT $$"));
    std::optional<std::string> problem = vdbCrashCheck(file, "density");
    ASSERT_TRUE(problem.has_value());
    EXPECT_NE(problem->find("SIGABRT"), std::string::npos) << *problem;
}

TEST(VdbGuard, TheProbeGetsTheRealPathEveryGridAndTheVoxelCap) {
    std::string dir = testDir();
    GuardFixture guard(stubProbe(dir, "args", "exit 0"));
    std::filesystem::create_directories(dir + "/sub");
    writeFile(dir + "/sub/f.vdb", "x");
    GridMediumDesc desc;
    desc.filePath = dir + "/sub/../sub/f.vdb";
    desc.densityGrid = "smoke";
    desc.temperatureGrid = "heat";
    desc.albedoGrid = "tint";
    desc.maxActiveVoxels = 1234;
    EXPECT_EQ(vdbCrashCheck(desc), std::nullopt);
    std::string real = std::filesystem::canonical(dir + "/sub/f.vdb").string();
    EXPECT_EQ(readFile(dir + "/args.log"), real + " smoke --temperature heat --albedo tint --max-voxels 1234\n");
}

TEST(VdbGuard, ConcurrentChecksAgree) {
    std::string dir = testDir();
    GuardFixture guard(stubProbe(dir, "segv", "kill -SEGV $$"));
    std::vector<std::string> files;
    for (int i = 0; i < 4; ++i) {
        files.push_back(dir + "/f" + std::to_string(i) + ".vdb");
        writeFile(files.back(), std::string(size_t(i + 1), 'x'));
    }
    std::atomic<int> crashes{0};
    std::vector<std::thread> threads;
    for (int t = 0; t < 8; ++t)
        threads.emplace_back([&, t] {
            for (int k = 0; k < 4; ++k) {
                std::optional<std::string> p = vdbCrashCheck(files[size_t((t + k) % 4)], "density");
                if (p && p->find("SIGSEGV") != std::string::npos) ++crashes;
            }
        });
    for (std::thread& th : threads) th.join();
    EXPECT_EQ(crashes.load(), 32);
    // Each file is probed at least once and at most once per thread that missed the cache.
    size_t runs = countLines(dir + "/segv.log");
    EXPECT_GE(runs, 4u);
    EXPECT_LE(runs, 32u);
}

TEST(VdbGuard, ARealFileThatCrashesTheReaderIsReported) {
    // The 16^3 procedural cloud with one byte of its compressed voxel data changed: OpenVDB 10's
    // reader corrupts its heap on it and the probe aborts (loaded in this process it throws a
    // clean-looking error and the process may crash later). Found by byte-flip fuzzing.
    GuardFixture guard("");
    std::string path = testDir() + "/crash.vdb";
    writeProceduralCloudVdb(path, 16, 1.0 / 16, 1);
    std::string bytes = readFile(path);
    ASSERT_EQ(bytes.size(), 15650u) << "the procedural cloud changed: find another crashing byte";
    ASSERT_EQ(bytes[9036], '\0');
    bytes[9036] = char(26);
    writeFile(path, bytes);
    std::optional<std::string> problem = vdbCrashCheck(path, "density");
    ASSERT_TRUE(problem.has_value()) << "the file no longer crashes the reader (another OpenVDB?)";
    EXPECT_NE(problem->find("crashed on this file (SIG"), std::string::npos) << *problem;
}

TEST(VdbGuard, TheProbeInheritsNoDescriptorButTheStandardOnes) {
    // A host's pipe (inheritable: no O_CLOEXEC) must not stay open in a probe that hangs until its
    // time-out, or a caller reading that pipe to its end would wait for the probe too.
    std::string dir = testDir();
    GuardFixture guard(stubProbe(dir, "fds", "ls /proc/$$/fd > '" + dir + "/fds.txt'"));
    int ends[2];
    ASSERT_EQ(::pipe(ends), 0);
    ASSERT_EQ(::dup2(ends[0], 57), 57);
    ASSERT_EQ(::dup2(ends[1], 58), 58);
    writeFile(dir + "/f.vdb", "x");
    EXPECT_EQ(vdbCrashCheck(dir + "/f.vdb", "density"), std::nullopt);
    for (int fd : {ends[0], ends[1], 57, 58}) ::close(fd);
    std::string text = readFile(dir + "/fds.txt");
    std::set<std::string> open;
    std::istringstream lines(text);
    for (std::string line; std::getline(lines, line);) open.insert(line);
    ASSERT_TRUE(open.count("0") && open.count("1") && open.count("2")) << text;
    EXPECT_EQ(open.count("57"), 0u) << text;
    EXPECT_EQ(open.count("58"), 0u) << text;
}
