#include "core/vdbGuard.h"

#include <dlfcn.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>
#include <vector>

#include "core/diagnostics.h"

extern char** environ;

namespace volphoton {
namespace {

constexpr const char* kProbeName = "volphoton-vdbprobe";
constexpr const char* kProbeEnv = "HDVOLPHOTON_VDBPROBE";

/// How one probe run ended.
struct ProbeOutcome {
    enum class Kind {
        Clean,      ///< exit status 0: the file loaded or was refused with an exception
        Signalled,  ///< killed by `signal`: the reader crashed
        TimedOut,   ///< still running at the deadline, killed
        Unusable,   ///< not started, or ended otherwise: says nothing about the file (`why`)
    };
    Kind kind = Kind::Unusable;
    int signal = 0;
    std::string why;
};

std::mutex& guardMutex() {
    static std::mutex m;
    return m;
}

/// Cache key -> verdict; guarded by guardMutex().
std::map<std::string, std::optional<std::string>>& verdictCache() {
    static std::map<std::string, std::optional<std::string>> cache;
    return cache;
}

/// Warns once per distinct message (a missing probe must not flood a frame range); thread-safe.
void warnOnce(const std::string& message) {
    static std::set<std::string> warned;
    {
        std::lock_guard<std::mutex> lock(guardMutex());
        if (!warned.insert(message).second) return;
    }
    warn(message);
}

/// "SIGSEGV" for the signals a crashing reader dies of, else "signal N".
std::string signalName(int sig) {
    static const std::pair<int, const char*> names[] = {
        {SIGSEGV, "SIGSEGV"}, {SIGBUS, "SIGBUS"},   {SIGABRT, "SIGABRT"}, {SIGFPE, "SIGFPE"},
        {SIGILL, "SIGILL"},   {SIGKILL, "SIGKILL"}, {SIGTERM, "SIGTERM"}, {SIGTRAP, "SIGTRAP"},
        {SIGSYS, "SIGSYS"},   {SIGXCPU, "SIGXCPU"}, {SIGXFSZ, "SIGXFSZ"}, {SIGINT, "SIGINT"}};
    for (const auto& [number, name] : names)
        if (number == sig) return name;
    return "signal " + std::to_string(sig);
}

/// The folders that may hold the probe: that of the module containing this code (a shared object
/// such as _core*.so or hdVolPhoton.so, or an executable), then that of the running executable
/// (dladdr names the main program by argv[0], which may be relative to another folder).
std::vector<std::filesystem::path> probeFolders() {
    std::vector<std::filesystem::path> folders;
    std::error_code ec;
    Dl_info info{};
    if (dladdr(reinterpret_cast<void*>(&probeFolders), &info) && info.dli_fname && info.dli_fname[0]) {
        std::filesystem::path module = std::filesystem::canonical(info.dli_fname, ec);
        if (!ec) folders.push_back(module.parent_path());
    }
    std::filesystem::path exe = std::filesystem::canonical("/proc/self/exe", ec);
    if (!ec) folders.push_back(exe.parent_path());
    return folders;
}

/// volphoton-vdbprobe next to the module, searched once per process (the module does not move).
const std::string& bundledProbePath() {
    static const std::string path = [] {
        for (const std::filesystem::path& folder : probeFolders()) {
            std::filesystem::path candidate = folder / kProbeName;
            if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
        }
        return std::string();
    }();
    return path;
}

/// Runs `args` (args[0] = the executable) with stdin, stdout and stderr on /dev/null and no other
/// descriptor, the host's environment, an empty signal mask and default signal actions; kills it at
/// the deadline.
ProbeOutcome runProbe(const std::vector<std::string>& args, double timeoutSeconds) {
    ProbeOutcome outcome;
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);

    posix_spawn_file_actions_t files;
    posix_spawn_file_actions_init(&files);
    posix_spawn_file_actions_addopen(&files, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&files, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_adddup2(&files, 1, 2);
#if defined(__GLIBC__) && (__GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 34))
    // The host's other descriptors (pipes a caller reads to EOF, sockets) stay the host's.
    posix_spawn_file_actions_addclosefrom_np(&files, 3);
#endif
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    sigset_t none, all;
    sigemptyset(&none);
    sigfillset(&all);
    sigdelset(&all, SIGKILL);
    sigdelset(&all, SIGSTOP);
    posix_spawnattr_setsigmask(&attr, &none);    // the host may block signals in this thread
    posix_spawnattr_setsigdefault(&attr, &all);  // ... or ignore some (a crash must still kill the probe)
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
    pid_t pid = 0;
    int err = posix_spawn(&pid, argv[0], &files, &attr, argv.data(), environ);
    posix_spawnattr_destroy(&attr);
    posix_spawn_file_actions_destroy(&files);
    if (err != 0) {
        outcome.why = "cannot start " + args[0] + ": " + std::strerror(err);
        return outcome;
    }

    // Poll rather than block: waitpid has no time-out, and a SIGALRM or a helper thread would touch
    // the host's signal handling. The probe takes a few tenths of a second at least, so polling at
    // most every 20 ms costs little.
    using Clock = std::chrono::steady_clock;
    const Clock::time_point deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                          std::chrono::duration<double>(timeoutSeconds));
    std::chrono::milliseconds pause(1);
    int status = 0;
    for (;;) {
        pid_t r = ::waitpid(pid, &status, WNOHANG);
        if (r == pid) break;
        if (r < 0 && errno != EINTR) {
            // ECHILD: the host reaps children itself (SIGCHLD ignored or a reaping handler).
            outcome.why = std::string("cannot wait for ") + args[0] + ": " + std::strerror(errno);
            ::kill(pid, SIGKILL);
            return outcome;
        }
        Clock::time_point now = Clock::now();
        if (now >= deadline) {
            ::kill(pid, SIGKILL);
            while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
            }
            outcome.kind = ProbeOutcome::Kind::TimedOut;
            return outcome;
        }
        std::this_thread::sleep_for(std::min<Clock::duration>(pause, deadline - now));
        pause = std::min(pause * 2, std::chrono::milliseconds(20));
    }
    if (WIFSIGNALED(status)) {
        outcome.kind = ProbeOutcome::Kind::Signalled;
        outcome.signal = WTERMSIG(status);
    } else if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
        outcome.kind = ProbeOutcome::Kind::Clean;
    } else {
        outcome.why = args[0] + " ended with exit status " + std::to_string(WEXITSTATUS(status));
    }
    return outcome;
}

std::string formatSeconds(double s) {
    std::ostringstream out;
    out << s;  // 60 -> "60", 0.5 -> "0.5"
    return out.str();
}

}  // namespace

std::string vdbProbePath() {
    const char* over = std::getenv(kProbeEnv);
    if (over && over[0]) return over;
    return bundledProbePath();
}

std::optional<std::string> vdbCrashCheck(const GridMediumDesc& desc, double timeoutSeconds) {
    struct stat st{};
    if (::stat(desc.filePath.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return std::nullopt;  // the load reports it
    std::error_code ec;
    std::filesystem::path real = std::filesystem::canonical(desc.filePath, ec);
    if (ec) return std::nullopt;
    std::ostringstream key;
    key << real.string() << '\n'
        << st.st_size << '\n'
        << st.st_mtim.tv_sec << '.' << st.st_mtim.tv_nsec << '\n'
        << desc.densityGrid << '\n'
        << desc.temperatureGrid << '\n'
        << desc.emissionGrid << '\n'
        << desc.albedoGrid << '\n'
        << desc.maxActiveVoxels;
    {
        std::lock_guard<std::mutex> lock(guardMutex());
        auto hit = verdictCache().find(key.str());
        if (hit != verdictCache().end()) return hit->second;
    }

    std::string probe = vdbProbePath();
    if (probe.empty()) {
        warnOnce(std::string("the VDB reader guard is off: ") + kProbeName + " was not found next to the renderer (set " +
                 kProbeEnv + " to its path); VDB files are read without the guard, and a corrupt one may crash");
        return std::nullopt;
    }
    // The path as the host resolved it, so a relative filePath means the same file to the probe.
    std::vector<std::string> args = {probe, real.string(), desc.densityGrid};
    for (auto [option, grid] : {std::pair<const char*, const std::string*>{"--temperature", &desc.temperatureGrid},
                                {"--emission", &desc.emissionGrid},
                                {"--albedo", &desc.albedoGrid}}) {
        if (!grid->empty()) {
            args.push_back(option);
            args.push_back(*grid);
        }
    }
    args.push_back("--max-voxels");
    args.push_back(std::to_string(desc.maxActiveVoxels));

    const double limit = timeoutSeconds > 0 ? timeoutSeconds : kVdbProbeTimeoutSeconds;
    ProbeOutcome outcome = runProbe(args, limit);
    std::optional<std::string> verdict;
    switch (outcome.kind) {
    case ProbeOutcome::Kind::Clean:
        break;
    case ProbeOutcome::Kind::Signalled:
        verdict = "the OpenVDB reader crashed on this file (" + signalName(outcome.signal) +
                  "): its voxel data is corrupt";
        break;
    case ProbeOutcome::Kind::TimedOut:
        verdict = "reading the file took longer than " + formatSeconds(limit) +
                  " s: its voxel data is corrupt or enormous";
        break;
    case ProbeOutcome::Kind::Unusable:
        // Says nothing about the file: not cached, so a repaired probe is used from the next check on.
        warnOnce("the VDB reader guard could not run its probe (" + outcome.why +
                 "); VDB files are read without the guard, and a corrupt one may crash");
        return std::nullopt;
    }
    std::lock_guard<std::mutex> lock(guardMutex());
    verdictCache()[key.str()] = verdict;
    return verdict;
}

std::optional<std::string> vdbCrashCheck(const std::string& path, const std::string& densityGrid,
                                         double timeoutSeconds) {
    GridMediumDesc desc;
    desc.filePath = path;
    desc.densityGrid = densityGrid;
    return vdbCrashCheck(desc, timeoutSeconds);
}

void clearVdbCrashCheckCache() {
    std::lock_guard<std::mutex> lock(guardMutex());
    verdictCache().clear();
}

}  // namespace volphoton
