// The run directory (run_evolution, run_search): config.toml, history.csv, the best's lineage,
// checkpoints, resumes and the directory's lock, around the GA engine of evolution.cpp and the
// other searches of search.hpp.
#include "animat/run.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numeric>
#include <sstream>

#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "animat/islands.hpp"
#include "animat/run_identity.hpp"

namespace animat {

using nlohmann::json;

namespace {

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

namespace {

// The temporary file of an atomic write: named after the writing process, so that no two processes
// ever write the same temporary file (the run directory's lock keeps them apart anyway).
std::filesystem::path temporary_name(const std::filesystem::path& path) {
  return path.string() + "." + std::to_string(::getpid()) + ".tmp";
}

// Writes via a temporary file, fsync and rename: the target is either the old or the new file.
void write_atomically(const std::filesystem::path& path, std::string_view content) {
  const std::filesystem::path tmp = temporary_name(path);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0)
    throw IoError(fmt::format("{}: cannot write: {}", tmp.string(), std::strerror(errno)));
  std::size_t done = 0;
  while (done < content.size()) {
    const ssize_t w = ::write(fd, content.data() + done, content.size() - done);
    if (w < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd);
      ::unlink(tmp.c_str());
      throw IoError(fmt::format("{}: write failed: {}", tmp.string(), std::strerror(err)));
    }
    done += static_cast<std::size_t>(w);
  }
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    throw IoError(fmt::format("{}: flush failed: {}", tmp.string(), std::strerror(err)));
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    throw IoError(fmt::format("{}: rename failed: {}", path.string(), std::strerror(err)));
  }
}

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(fmt::format("{}: cannot open", path.string()));
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// history.csv's columns and rows, from GenerationStats' descriptor. `protecting`: the run has
// morphological innovation protection (evolution.protection_generations > 0), whose columns only
// its history.csv holds.
bool history_column(const StatsField& f, bool protecting) {
  return f.csv && (protecting || !f.protection_only);
}

std::string history_header(bool protecting) {
  std::string out;
  GenerationStats probe;
  visit_fields(probe, [&](const StatsField& f, const auto&) {
    if (history_column(f, protecting)) out += (out.empty() ? "" : ",") + std::string(f.name);
  });
  return out + "\n";
}

std::string history_row(const GenerationStats& s, bool protecting) {
  std::string out;
  visit_fields(s, [&](const StatsField& f, const auto& value) {
    if (!history_column(f, protecting)) return;
    if (!out.empty()) out += ',';
    if constexpr (std::is_floating_point_v<std::decay_t<decltype(value)>>) {
      if (f.decimals >= 0) {
        out += fmt::format("{:.{}f}", value, f.decimals);
        return;
      }
    }
    out += fmt::format("{}", value);
  });
  return out + "\n";
}

void append(const std::filesystem::path& path, std::string_view text) {
  std::ofstream out(path, std::ios::app | std::ios::binary);
  if (!out || !(out << text) || !out.flush())
    throw IoError(fmt::format("{}: cannot append", path.string()));
}

void write_lineage(const std::filesystem::path& dir, const Evolution& evo, bool protecting) {
  const Individual& b = evo.best();
  json j{{"generation", evo.generation()},
         {"fitness", b.result.fitness},
         {"reference_fitness", std::isnan(b.reference) ? json(nullptr) : json(b.reference)},
         {"cell_count", b.result.cell_count},
         {"id", b.id},
         {"genome", json::parse(to_json(b.genome))}};
  if (protecting) {  // other runs write the file as before
    j["morphology_kind"] = b.result.morphology_kind;
    j["morphology_age"] = b.morphology_age;
  }
  write_atomically(dir / "best" / fmt::format("gen_{:06d}.json", evo.generation()),
                   j.dump(1) + "\n");
}

// genealogy.csv: one row per individual born (the initial population, then each generation's
// offspring; an elite or migrant copy is not born again), so the family tree of any individual can
// be traced through the parent ids. Rows after the checkpoint are dropped on resume, as
// history.csv's. A run with morphological innovation protection adds each newborn's morphology kind
// and age (0, or its parent's + 1); other runs write the file as before.
class GenealogyLog {
 public:
  static constexpr std::string_view kHeader = "generation,id,parent_a,parent_b,fitness,cells\n";
  static constexpr std::string_view kProtectionHeader =
      "generation,id,parent_a,parent_b,fitness,cells,morphology_kind,morphology_age\n";
  GenealogyLog(std::filesystem::path path, bool protecting)
      : path_(std::move(path)), protecting_(protecting) {}

  void start(const Evolution& evo) const {
    write_atomically(path_, std::string(header()) + rows(evo));
  }
  void resume(int generation) const {
    std::string kept(header());
    std::ifstream in(path_, std::ios::binary);
    std::string line;
    for (bool header = true; std::getline(in, line); header = false) {
      int g = -1;
      if (!header && std::sscanf(line.c_str(), "%d,", &g) == 1 && g <= generation)
        kept += line + "\n";
    }
    in.close();
    write_atomically(path_, kept);
  }
  void append(const Evolution& evo) const { ::animat::append(path_, rows(evo)); }

 private:
  [[nodiscard]] std::string_view header() const {
    return protecting_ ? kProtectionHeader : kHeader;
  }
  std::string rows(const Evolution& evo) const {
    const auto& pop = evo.population();
    const auto n = static_cast<std::int64_t>(pop.size());
    const std::int64_t first = static_cast<std::int64_t>(evo.generation()) * n;
    std::vector<bool> written(pop.size(), false);
    std::string out;
    for (const Individual& ind : pop) {
      if (ind.id < first || ind.id >= first + n) continue;  // born earlier: an elite
      const auto slot = static_cast<std::size_t>(ind.id - first);
      if (written[slot]) continue;  // a migrant's second copy
      written[slot] = true;
      out += fmt::format("{},{},{},{},{},{}", evo.generation(), ind.id, ind.parent_a, ind.parent_b,
                         ind.result.fitness, ind.result.cell_count);
      out += protecting_ ? fmt::format(",{},{}\n", ind.result.morphology_kind, ind.morphology_age)
                         : std::string("\n");
    }
    return out;
  }
  std::filesystem::path path_;
  bool protecting_;
};

std::string duration(double s) {
  const auto t = static_cast<long long>(std::max(0.0, s));
  return fmt::format("{}:{:02d}:{:02d}", t / 3600, (t / 60) % 60, t % 60);
}

}  // namespace

namespace {

// A run directory the file system can hold: every component within NAME_MAX, the whole within
// PATH_MAX (with room for "/best/gen_000000.json.PID.tmp"). Checked before anything is created.
void check_run_path(const std::filesystem::path& dir) {
  auto shown = [](const std::string& s) { return s.size() > 60 ? s.substr(0, 57) + "..." : s; };
  for (const auto& part : dir) {
    const std::string name = part.string();
    if (name.size() > static_cast<std::size_t>(NAME_MAX))
      throw IoError(fmt::format(
          "{}: a component of the run directory's path has {} characters; the file system allows "
          "at most {} (NAME_MAX)",
          shown(dir.string()), name.size(), NAME_MAX));
  }
  std::error_code ec;
  const std::filesystem::path absolute = std::filesystem::absolute(dir, ec);
  const std::size_t length = (ec ? dir : absolute).string().size() + 48;
  if (length > static_cast<std::size_t>(PATH_MAX))
    throw IoError(fmt::format(
        "{}: the run directory's path has {} characters; with its file names it must stay within "
        "{} (PATH_MAX)",
        shown(dir.string()), length - 48, PATH_MAX));
}

// Refuses a resume whose settings differ from the run's own config.toml in a key that defines the
// run, naming every such key; returns the resumable keys that changed (accepted).
std::vector<std::string> check_resume_settings(const Config& config,
                                               const std::filesystem::path& dir) {
  const std::filesystem::path stored_path = dir / "config.toml";
  std::error_code ec;
  // the checkpoint's identity still decides
  if (!std::filesystem::exists(stored_path, ec)) return {};
  const Config stored = load_config(stored_path);
  const auto& resumable = resumable_keys();
  std::vector<std::string> refused, accepted;
  for (const auto& key : config_differences(stored, config)) {
    const bool may_change = std::find(resumable.begin(), resumable.end(), key) != resumable.end();
    (may_change ? accepted : refused).push_back(key);
  }
  if (!refused.empty()) {
    std::vector<std::string> parts;
    for (const auto& key : refused)
      parts.push_back(fmt::format("{} (the run has {}, this command gives {})", key,
                                  format_config_value(get_value(stored, key)),
                                  format_config_value(get_value(config, key))));
    throw ConfigError(
        fmt::format("{}: cannot resume with changed settings: {}. Only {} may change on resume; "
                    "start a new run (another --out) "
                    "to change the others. Nothing was written.",
                    dir.string(), fmt::join(parts, ", "), fmt::join(resumable, ", ")));
  }
  return accepted;
}

// ---------------------------------------------------------------------------------------------------
// One writer per run directory: an advisory lock (flock) on RUN/.lock, held for the run's life. The
// kernel drops it when its process ends, however it ends, so the lock of a killed run is taken over
// at once. The file names its holder (pid, host) for the message of a refused second writer.
constexpr const char* kLockName = ".lock";

// "pid 123 on host h" from a lock file's text; the holder may not have written it yet.
std::string lock_holder(int fd) {
  char buf[512];
  const ssize_t n = ::pread(fd, buf, sizeof buf - 1, 0);
  const std::string text(buf, n > 0 ? static_cast<std::size_t>(n) : 0);
  long long pid = 0;
  char host[256] = {};
  if (std::sscanf(text.c_str(), "pid %lld host %255s", &pid, host) == 2 && pid > 0)
    return fmt::format("pid {} on host {}", pid, host);
  return "a process that is just starting (no pid recorded yet)";
}

[[noreturn]] void throw_busy(const std::filesystem::path& dir, const std::string& holder) {
  throw RunDirectoryBusy(
      fmt::format("{}: the run directory is in use by another animat process ({}, holding {}); one "
                  "process writes a run "
                  "directory at a time. Wait for it to end or stop it (Ctrl-C or kill -TERM "
                  "checkpoints), then resume; or use "
                  "another directory. Nothing was written.",
                  dir.string(), holder, (dir / kLockName).string()));
}

// Refuses a directory another process holds, without creating or changing any file.
void probe_lock(const std::filesystem::path& dir) {
  const std::filesystem::path path = dir / kLockName;
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
  if (fd < 0) return;  // no lock file (or none we can read: RunLock decides)
  if (::flock(fd, LOCK_SH | LOCK_NB) != 0) {
    const int err = errno;
    const std::string holder = lock_holder(fd);
    ::close(fd);
    if (err == EWOULDBLOCK) throw_busy(dir, holder);
    return;
  }
  ::close(fd);  // releases the shared lock
}

class RunLock {
 public:
  explicit RunLock(const std::filesystem::path& dir) : path_(dir / kLockName) {
    for (int attempt = 0;; ++attempt) {
      created_ = false;
      fd_ = ::open(path_.c_str(), O_RDWR | O_CLOEXEC | O_NOFOLLOW);
      if (fd_ < 0 && errno == ENOENT) {
        fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, 0644);
        // another process made it just now
        if (fd_ < 0 && errno == EEXIST && attempt < 100) continue;
        created_ = fd_ >= 0;
      }
      if (fd_ < 0)
        throw IoError(fmt::format("{}: cannot open the run directory's lock file: {}",
                                  path_.string(), std::strerror(errno)));
      if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
        const int err = errno;
        const std::string holder = lock_holder(fd_);
        ::close(fd_);
        fd_ = -1;
        if (err == EWOULDBLOCK) throw_busy(dir, holder);
        throw IoError(fmt::format("{}: cannot lock the run directory: {}", path_.string(),
                                  std::strerror(err)));
      }
      // Its last holder removes the file on release: make sure the file locked is the one on disk.
      struct stat held{}, on_disk{};
      if (::fstat(fd_, &held) == 0 && ::stat(path_.c_str(), &on_disk) == 0 &&
          held.st_dev == on_disk.st_dev && held.st_ino == on_disk.st_ino)
        break;
      ::close(fd_);
      fd_ = -1;
      if (attempt >= 100)
        throw IoError(
            fmt::format("{}: cannot lock the run directory: the lock file keeps being replaced",
                        path_.string()));
    }
    char host[256] = {};
    if (::gethostname(host, sizeof host - 1) != 0 || host[0] == '\0') std::strcpy(host, "unknown");
    const std::string text = fmt::format("pid {}\nhost {}\n", ::getpid(), host);
    // Best effort: the lock holds without it; only the message of a refused writer would lack the
    // pid.
    if (::ftruncate(fd_, 0) == 0) {
      const ssize_t written = ::pwrite(fd_, text.data(), text.size(), 0);
      (void)written;
    }
  }
  RunLock(const RunLock&) = delete;
  RunLock& operator=(const RunLock&) = delete;
  /// Every check passed: the run owns the directory, and removes the lock file when it ends.
  void started() { started_ = true; }
  ~RunLock() {
    if (fd_ < 0) return;
    // A refused command leaves a lock file it found (a killed run's) as it was.
    if (created_ || started_) ::unlink(path_.c_str());
    ::close(fd_);
  }

 private:
  std::filesystem::path path_;
  int fd_ = -1;
  bool created_ = false, started_ = false;
};

// What a run writes into its directory (RunOptions::overwrite removes these and nothing else).
const std::vector<std::string> kRunFiles = {
    "config.toml", "history.csv", "checkpoint.json", "islands.csv", "genealogy.csv", "resume.log",
    "stopped.txt", "best",        "figures",         "archive",     "front"};

// NAME.PID.tmp or NAME.tmp next to a run file: left by a process killed while writing NAME.
bool is_leftover_temporary(const std::string& name) {
  if (name.size() < 5 || name.compare(name.size() - 4, 4, ".tmp") != 0) return false;
  std::string stem = name.substr(0, name.size() - 4);
  if (const auto dot = stem.rfind('.');
      dot != std::string::npos && dot + 1 < stem.size() &&
      stem.find_first_not_of("0123456789", dot + 1) == std::string::npos)
    stem.resize(dot);
  if (stem.rfind("gen_", 0) == 0) return true;
  return std::find(kRunFiles.begin(), kRunFiles.end(), stem) != kRunFiles.end();
}

// Removes the temporary files of killed writers (the lock is held: no live writer has any).
void remove_leftover_temporaries(const std::filesystem::path& dir) {
  for (const auto& folder : {dir, dir / "best"}) {
    std::error_code ec;
    if (!std::filesystem::is_directory(folder, ec)) continue;
    std::vector<std::filesystem::path> doomed;
    for (const auto& entry : std::filesystem::directory_iterator(folder))
      if (is_leftover_temporary(entry.path().filename().string()) && !entry.is_directory(ec))
        doomed.push_back(entry.path());
    for (const auto& p : doomed) std::filesystem::remove(p);
  }
}

std::size_t history_rows(const std::filesystem::path& path, bool* only_generation_zero) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  std::size_t rows = 0;
  *only_generation_zero = true;
  for (bool header = true; std::getline(in, line); header = false) {
    if (header || line.empty()) continue;
    ++rows;
    if (line.rfind("0,", 0) != 0) *only_generation_zero = false;
  }
  return rows;
}

// A fresh run may start in `dir` when it holds no run: nothing of one, or exactly what this same
// command leaves when stopped before its first checkpoint (its config.toml, generation 0 at most),
// which it would write again identically. Otherwise refuses, naming what is there.
void refuse_existing_run(const Config& config, const std::filesystem::path& dir) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) return;
  if (std::filesystem::exists(dir / "checkpoint.json", ec))
    throw RunExists(fmt::format(
        "{}: already holds a run (checkpoint.json); resume it (--resume {} / resume=True), replace "
        "it (--overwrite / overwrite=True) or choose another directory. Nothing was written.",
        dir.string(), dir.string()));
  std::vector<std::string> found;
  bool restartable = true;
  const std::filesystem::path stored = dir / "config.toml";
  if (std::filesystem::exists(stored, ec)) {
    std::string why;
    try {
      const auto keys = config_differences(load_config(stored), config);
      if (!keys.empty())
        why = fmt::format(
            "a different config: {}{}",
            fmt::join(keys.begin(), keys.begin() + std::min<std::size_t>(keys.size(), 4), ", "),
            keys.size() > 4 ? fmt::format(" and {} more", keys.size() - 4) : "");
    } catch (const Error&) {
      why = "not a valid config";
    }
    found.push_back(why.empty() ? "config.toml" : fmt::format("config.toml ({})", why));
    restartable = why.empty();
  } else {
    restartable = false;  // results without their config
  }
  bool zero_only = true;
  if (std::filesystem::exists(dir / "history.csv", ec)) {
    const std::size_t rows = history_rows(dir / "history.csv", &zero_only);
    found.push_back(fmt::format("history.csv ({} generation{})", rows, rows == 1 ? "" : "s"));
    if (rows > 1 || !zero_only) restartable = false;
  }
  if (std::filesystem::is_directory(dir / "best", ec)) {
    std::size_t files = 0;
    bool beyond_zero = false;
    for (const auto& entry : std::filesystem::directory_iterator(dir / "best")) {
      const std::string name = entry.path().filename().string();
      if (is_leftover_temporary(name)) continue;
      ++files;
      if (name != "gen_000000.json") beyond_zero = true;
    }
    if (files > 0) found.push_back(fmt::format("best/ ({} file{})", files, files == 1 ? "" : "s"));
    if (beyond_zero) restartable = false;
  }
  for (const char* log : {"islands.csv", "genealogy.csv"}) {
    if (!std::filesystem::exists(dir / log, ec)) continue;
    (void)history_rows(dir / log, &zero_only);
    found.push_back(log);
    if (!zero_only) restartable = false;
  }
  if (std::filesystem::exists(dir / "resume.log", ec)) {
    found.push_back("resume.log");
    restartable = false;
  }
  if (found.empty() || restartable) return;
  throw RunExists(
      fmt::format("{}: holds the files of a run but no checkpoint.json to resume from: {}; "
                  "starting a new run here would mix two "
                  "runs. Replace it (--overwrite / overwrite=True) or choose another directory. "
                  "Nothing was written.",
                  dir.string(), fmt::join(found, ", ")));
}

// RunOptions::overwrite: removes what a run wrote, nothing else.
void clear_run_directory(const std::filesystem::path& dir) {
  for (const auto& name : kRunFiles) std::filesystem::remove_all(dir / name);
  remove_leftover_temporaries(dir);
}

std::string local_time_stamp() {
  const std::time_t t = std::time(nullptr);
  char stamp[32];
  std::tm tm{};
  localtime_r(&t, &tm);
  std::strftime(stamp, sizeof stamp, "%Y-%m-%d %H:%M:%S", &tm);
  return stamp;
}

}  // namespace

namespace {

// Everything in the run directory that can refuse the command, before any file is written: on
// resume, the directory, its checkpoint (whose text is returned) and the settings (the accepted
// changes go to `changed`); otherwise an existing run, unless it is to be overwritten.
std::string check_run_directory(const Config& config, const RunOptions& opt,
                                std::vector<std::string>& changed) {
  std::error_code ec;
  if (opt.resume) {
    if (!std::filesystem::is_directory(opt.out, ec))
      throw IoError(fmt::format("{}: resume directory does not exist", opt.out.string()));
    const std::filesystem::path ckpt = opt.out / "checkpoint.json";
    if (!std::filesystem::exists(ckpt, ec))
      throw CheckpointError(fmt::format("{}: no checkpoint.json to resume from", opt.out.string()));
    changed = check_resume_settings(config, opt.out);
    return read_file(ckpt);
  }
  if (!opt.overwrite) refuse_existing_run(config, opt.out);
  return {};
}

// resume.log: the settings a resume changed (accepted by check_resume_settings), one line.
void note_resume(const Config& config, const RunOptions& opt, const std::string& tag,
                 int generation, const std::vector<std::string>& changed) {
  if (changed.empty()) return;
  const Config stored = load_config(opt.out / "config.toml");
  std::string note = fmt::format("{} resumed at generation {}:", local_time_stamp(), generation);
  for (const auto& key : changed) {
    note += fmt::format(" {} {} -> {};", key, format_config_value(get_value(stored, key)),
                        format_config_value(get_value(config, key)));
    if (!opt.quiet)
      spdlog::info("{}resume: {} changed from {} to {}", tag, key,
                   format_config_value(get_value(stored, key)),
                   format_config_value(get_value(config, key)));
  }
  note.back() = '\n';
  append(opt.out / "resume.log", note);
}

RunSummary run_evolution_unchecked(const Config& config, const RunOptions& opt,
                                   FitnessFunction fitness, FitnessFunction reference) {
  validate(config);
  require_ga(config);
  GenomeKey key = opt.fitness_key;
  if (!fitness) {
    // the real swim: its exploit guard re-evaluates each new best at the reference step
    fitness = swim_fitness(config);
    if (config.evaluation.reference_check != "off")
      reference = swim_fitness(reference_config(config));
    key = evaluation_key(config);
  }
  Evolution evo(config, std::move(fitness), std::move(reference), opt.evaluator);
  evo.set_stop(StopRequest{opt.stop_flag, opt.stop_poll});
  evo.set_fitness_key(std::move(key));
  const std::string tag = opt.label.empty() ? std::string() : "[" + opt.label + "] ";
  const bool writing = !opt.out.empty();
  // [islands] islands.csv
  IslandLog island_log(writing ? opt.out : std::filesystem::path{}, config.evolution);
  // [protection] history.csv, genealogy.csv and the lineage carry the protection's columns
  const bool protecting = config.evolution.protection_generations > 0;
  const GenealogyLog genealogy(opt.out / "genealogy.csv", protecting);
  const std::filesystem::path ckpt = opt.out / "checkpoint.json", hist = opt.out / "history.csv";

  // 1. Everything that can refuse the command, before any file is written: checked once without the
  // run directory's lock (so that a refusal creates nothing, not even the lock file), then again
  // holding it (another process may have written in between).
  std::vector<std::string> changed_on_resume;
  if (opt.resume && !writing) throw Error("run_evolution: resume needs a run directory");
  if (opt.resume && opt.overwrite)
    throw Error("run_evolution: resume and overwrite contradict each other");
  std::optional<RunLock> lock;
  if (writing) {
    check_run_path(opt.out);
    std::error_code ec;
    // the checkpoint's text when resuming
    auto check = [&] { return check_run_directory(config, opt, changed_on_resume); };
    probe_lock(opt.out);
    std::string checkpoint_text = check();
    if (opt.resume) {
      evo.restore(checkpoint_text, ckpt.string());
      // Already at its cap, stalled or out of budget under these settings: nothing to evolve, so
      // the directory is left as it is (its config.toml keeps the settings it ran under).
      if (std::string reason = evo.stop_reason(); !reason.empty()) {
        if (!opt.quiet)
          spdlog::info("{}{} is at generation {}: {}; nothing to evolve, no file was written", tag,
                       opt.out.string(), evo.generation(), reason);
        RunSummary summary;
        summary.stop_reason = std::move(reason);
        summary.history = evo.history();
        summary.best = evo.best();
        summary.population = evo.population();
        return summary;
      }
    }
    if (!opt.resume) {
      std::filesystem::create_directories(opt.out, ec);
      if (ec)
        throw IoError(
            fmt::format("{}: cannot create run directory: {}", opt.out.string(), ec.message()));
    }
    lock.emplace(opt.out);
    if (const std::string again = check(); again != checkpoint_text)
      evo.restore(again, ckpt.string());
    lock->started();
    if (opt.on_start) opt.on_start();
    if (opt.overwrite) clear_run_directory(opt.out);
    remove_leftover_temporaries(opt.out);
  }

  // 2. Write.
  if (writing) {
    std::error_code ec;
    std::filesystem::create_directories(opt.out / "best", ec);
    if (ec)
      throw IoError(
          fmt::format("{}: cannot create run directory: {}", opt.out.string(), ec.message()));
    note_resume(config, opt, tag, evo.generation(), changed_on_resume);
    write_atomically(opt.out / "config.toml", to_toml(config));
  }

  if (opt.resume) {
    std::string rows(history_header(protecting));
    for (const auto& s : evo.history()) rows += history_row(s, protecting);
    write_atomically(hist, rows);  // drops rows written after the checkpoint
    island_log.resume(evo.generation());
    genealogy.resume(evo.generation());
    // Lineage files of generations after the checkpoint belong to the lost future; they are
    // rewritten.
    for (const auto& entry : std::filesystem::directory_iterator(opt.out / "best")) {
      const std::string name = entry.path().filename().string();
      int g = -1;
      if (std::sscanf(name.c_str(), "gen_%d.json", &g) == 1 && g > evo.generation())
        std::filesystem::remove(entry.path());
    }
    if (!opt.quiet)
      spdlog::info("{}resumed {} at generation {}", tag, opt.out.string(), evo.generation());
  } else {
    if (!opt.quiet)
      spdlog::info("{}drawing {} viable random individuals...", tag, config.evolution.population);
    try {
      evo.initialize();
    } catch (const Interrupted&) {
      if (!opt.quiet)
        spdlog::info(
            "{}stopped: interrupted before the initial population was complete (nothing to "
            "resume)",
            tag);
      RunSummary summary;
      summary.stop_reason = "interrupted";
      return summary;
    }
    const auto tries = evo.initial_tries();
    const double mean_tries =
        std::accumulate(tries.begin(), tries.end(), 0.0) / static_cast<double>(tries.size());
    if (!opt.quiet)
      spdlog::info(
          "{}initial population: {} random genomes drawn, {:.0f} per viable individual on average "
          "(paper: \"a few hundred\"); they are developed, only the viable ones swim",
          tag, evo.evaluations(), mean_tries);
    if (writing) {
      write_atomically(hist,
                       history_header(protecting) + history_row(evo.history().back(), protecting));
      write_lineage(opt.out, evo, protecting);
      island_log.start(evo);
      genealogy.start(evo);
      write_atomically(ckpt, evo.checkpoint());
    }
  }
  bool stopped_by_callback = false;
  if (!opt.resume && opt.callback && !opt.callback(evo.history().back(), evo))
    stopped_by_callback = true;

  RunSummary summary;
  double last_print = 0.0;
  int last_printed = -1;
  auto report = [&](const GenerationStats& s, bool force) {
    if (opt.quiet || s.generation == last_printed) return;
    const double t = now_seconds();
    if (!force && t - last_print < opt.progress_interval) return;
    last_print = t;
    last_printed = s.generation;
    // ETA from the last generation's pace (the initial draws are not a generation's pace).
    const auto& h = evo.history();
    const double pace = h.size() >= 2 ? h.back().wall_seconds - h[h.size() - 2].wall_seconds : 0.0;
    std::string left;
    if (config.evolution.generations > 0 && s.generation > 0 && pace > 0) {
      double eta = pace * (config.evolution.generations - s.generation);
      if (config.evolution.wall_seconds > 0)
        eta = std::min(eta, config.evolution.wall_seconds - s.wall_seconds);
      left = fmt::format(", ETA {}", duration(eta));
    } else if (config.evolution.wall_seconds > 0) {
      left = fmt::format(", {} left of budget",
                         duration(config.evolution.wall_seconds - s.wall_seconds));
    }
    // The rate counts swims: a non-viable offspring is only developed, and generation 0's thousands
    // of random draws are not a pace.
    spdlog::info(
        "{}gen {:5d} | best {:8.4f} mean {:8.4f} median {:8.4f} | viable {:5.1f}% | {:6.1f} "
        "swims/s | {} elapsed{}",
        tag, s.generation, s.best, s.mean, s.median, 100.0 * s.viable_fraction, s.swims_per_second,
        duration(s.wall_seconds), left);
  };
  // Exploit guard: a best whose fitness the reference step does not confirm is reported.
  const EvaluationParams& ev = config.evaluation;
  auto guard = [&](const GenerationStats& s) {
    if (opt.quiet || !s.best_changed || std::isnan(s.best_reference)) return;
    if (reference_disagrees(s.best, s.best_reference, ev))
      spdlog::warn(
          "{}gen {}: the new best's fitness {:.4f} is not confirmed at the reference step "
          "(physics.substeps x {}: {:.4f}, {:+.1f}%): its swim depends on the step size",
          tag, s.generation, s.best, ev.reference_substeps, s.best_reference,
          100.0 * (s.best - s.best_reference) / std::max(std::abs(s.best_reference), 1e-12));
  };
  report(evo.history().back(), true);
  guard(evo.history().back());
  int since_checkpoint = 0;
  bool dirty = false;
  while (true) {
    if (stopped_by_callback) {
      summary.stop_reason = "stopped by callback";
      break;
    }
    summary.stop_reason = evo.stop_reason();
    if (summary.stop_reason.empty() &&
        ((opt.stop_flag && opt.stop_flag->load()) || (opt.stop_poll && opt.stop_poll())))
      summary.stop_reason = "interrupted";
    if (!summary.stop_reason.empty()) break;
    GenerationStats s;
    try {
      s = evo.step();
    } catch (const Interrupted&) {
      // the generation in progress is dropped; resuming recomputes it
      summary.stop_reason = "interrupted";
      break;
    }
    report(s, false);
    guard(s);
    if (writing) {
      append(hist, history_row(s, protecting));
      island_log.append(evo);
      genealogy.append(evo);
      if (s.best_changed) write_lineage(opt.out, evo, protecting);
      dirty = true;
      if (++since_checkpoint >= config.evolution.checkpoint_every) {
        write_atomically(ckpt, evo.checkpoint());
        since_checkpoint = 0;
        dirty = false;
      }
    }
    if (opt.callback && !opt.callback(s, evo)) {
      summary.stop_reason = "stopped by callback";
      break;
    }
  }
  if (writing && dirty) write_atomically(ckpt, evo.checkpoint());
  report(evo.history().back(), true);
  if (!opt.quiet) {
    // The best's own generation: the last in which the best changed (the lineage's last file).
    const auto& h = evo.history();
    int found = 0;
    for (const auto& row : h)
      if (row.best_changed) found = row.generation;
    spdlog::info("{}stopped at generation {}: {}; best {:.4f} ({} cells), found at generation {}",
                 tag, h.back().generation, summary.stop_reason, evo.best().result.fitness,
                 evo.best().result.cell_count, found);
  }
  summary.history = evo.history();
  summary.best = evo.best();
  summary.population = evo.population();
  return summary;
}

// ---------------------------------------------------------------------------------------------------
// The other searches (search.hpp): the same run directory, lock, checks and checkpoints.

std::string search_header(const std::vector<HistoryColumn>& columns) {
  std::string out;
  for (const auto& c : columns) out += (out.empty() ? "" : ",") + c.name;
  return out + "\n";
}

std::string search_row(const std::vector<HistoryColumn>& columns, const std::vector<double>& row) {
  std::string out;
  for (std::size_t c = 0; c < columns.size(); ++c) {
    if (c > 0) out += ',';
    if (columns[c].integer)
      out += fmt::format("{}", static_cast<std::int64_t>(row[c]));
    else if (columns[c].name == "wall_seconds")  // as the GA's: the only machine-dependent column
      out += fmt::format("{:.3f}", row[c]);
    else
      out += fmt::format("{}", row[c]);
  }
  return out + "\n";
}

SearchSummary run_search_unchecked(const Config& config, const RunOptions& opt,
                                   FitnessFunction fitness, FitnessFunction reference) {
  validate(config);
  if (config.search.algorithm == "ga")
    throw ConfigError(
        "search.algorithm = \"ga\": run_search runs MAP-Elites and NSGA-II; the GA is "
        "run_evolution");
  const bool writing = !opt.out.empty();
  std::vector<std::string> changed_on_resume;
  if (opt.resume && !writing) throw Error("run_search: resume needs a run directory");
  if (opt.resume && opt.overwrite)
    throw Error("run_search: resume and overwrite contradict each other");
  // Everything that can refuse the command, before any file is written: the run directory (a
  // resume's settings first: a changed search.algorithm is named as such), then the search itself
  // (a [search] setting or size it refuses), then the checkpoint; checked again under the lock.
  auto check = [&] { return check_run_directory(config, opt, changed_on_resume); };
  std::string checkpoint_text;
  if (writing) {
    check_run_path(opt.out);
    probe_lock(opt.out);
    checkpoint_text = check();
  }
  std::unique_ptr<Search> made;
  if (opt.search == nullptr)
    made =
        make_search(config, std::move(fitness), std::move(reference), opt.evaluator, opt.supplied);
  else if (opt.search->algorithm() != config.search.algorithm || opt.search->generation() >= 0)
    throw Error(fmt::format(
        "run_search: the caller's search is {} at generation {}; a run starts a new {} search",
        opt.search->algorithm(), opt.search->generation(), config.search.algorithm));
  Search* const search = made ? made.get() : opt.search;
  if (!search->supplied().empty() && !opt.describe)
    throw Error(fmt::format(
        "run_search: the caller supplies {} ({}) but gives no describe hook",
        fmt::join(search->supplied(), ", "),
        config.search.algorithm == "nsga2" ? "search.objectives" : "search.descriptors"));
  if (search->supplied().empty() && opt.describe)
    throw Error("run_search: a describe hook, but the caller supplies no descriptor or criterion");
  search->set_stop(StopRequest{opt.stop_flag, opt.stop_poll});
  const std::string tag = opt.label.empty() ? std::string() : "[" + opt.label + "] ";
  const std::filesystem::path ckpt = opt.out / "checkpoint.json", hist = opt.out / "history.csv";
  const auto columns = search->history_columns();
  SearchSummary summary;
  summary.algorithm = config.search.algorithm;
  summary.columns = columns;
  auto finish = [&](std::string reason) {
    summary.stop_reason = std::move(reason);
    summary.history = search->history();
    summary.generation = search->generation();
    return summary;
  };
  std::optional<RunLock> lock;
  if (writing) {
    std::error_code ec;
    if (opt.resume) {
      search->restore(checkpoint_text, ckpt.string());
      if (std::string reason = search->stop_reason(); !reason.empty()) {
        if (!opt.quiet)
          spdlog::info("{}{} is at generation {}: {}; nothing to search, no file was written", tag,
                       opt.out.string(), search->generation(), reason);
        return finish(std::move(reason));
      }
    } else {
      std::filesystem::create_directories(opt.out, ec);
      if (ec)
        throw IoError(
            fmt::format("{}: cannot create run directory: {}", opt.out.string(), ec.message()));
    }
    lock.emplace(opt.out);
    if (const std::string again = check(); again != checkpoint_text)
      search->restore(again, ckpt.string());
    lock->started();
    if (opt.on_start) opt.on_start();
    if (opt.overwrite) clear_run_directory(opt.out);
    remove_leftover_temporaries(opt.out);
    note_resume(config, opt, tag, search->generation(), changed_on_resume);
    write_atomically(opt.out / "config.toml", to_toml(config));
    if (opt.resume) {
      std::string rows = search_header(columns);
      for (const auto& row : search->history()) rows += search_row(columns, row);
      write_atomically(hist, rows);  // drops rows written after the checkpoint
    }
  }
  if (!opt.quiet)
    spdlog::info("{}{} {} at generation {}", tag, opt.resume ? "resumed" : "started",
                 config.search.algorithm, search->generation());
  int since_checkpoint = 0;
  bool dirty = false;
  std::string reason;
  while (true) {
    reason = search->stop_reason();
    if (reason.empty() &&
        ((opt.stop_flag && opt.stop_flag->load()) || (opt.stop_poll && opt.stop_poll())))
      reason = "interrupted";
    if (!reason.empty()) break;
    try {
      search->step(opt.evaluate, opt.describe);
    } catch (const Interrupted&) {
      reason = "interrupted";  // the generation in progress is dropped; resuming recomputes it
      break;
    }
    const auto history = search->history();
    if (writing) {
      if (history.size() == 1)
        write_atomically(hist, search_header(columns) + search_row(columns, history.back()));
      else
        append(hist, search_row(columns, history.back()));
      dirty = true;
      if (++since_checkpoint >= config.evolution.checkpoint_every || history.size() == 1) {
        write_atomically(ckpt, search->checkpoint());
        since_checkpoint = 0;
        dirty = false;
      }
    }
    if (!opt.quiet) {
      std::string line;
      for (std::size_t c = 1; c < columns.size(); ++c)
        line += fmt::format(" {} {:.6g}", columns[c].name, history.back()[c]);
      spdlog::info("{}gen {:5d} |{}", tag, search->generation(), line);
    }
    if (opt.search_callback && !opt.search_callback(*search)) {
      reason = "stopped by callback";
      break;
    }
  }
  if (writing && dirty) write_atomically(ckpt, search->checkpoint());
  if (!opt.quiet) spdlog::info("{}stopped at generation {}: {}", tag, search->generation(), reason);
  return finish(std::move(reason));
}

}  // namespace

const std::vector<std::string>& run_file_names() { return kRunFiles; }

void require_ga(const Config& config) {
  if (config.search.algorithm != "ga")
    throw ConfigError(
        fmt::format("search.algorithm = \"{}\": this runs the GA; MAP-Elites and NSGA-II run by "
                    "animat_evolve (run_search) or in Python: `animat evolve` with the same flags "
                    "(python -m animat evolve), or animat.run_{} (docs/search.md)",
                    config.search.algorithm, config.search.algorithm));
}

SearchSummary run_search(const Config& config, const RunOptions& opt, FitnessFunction fitness,
                         FitnessFunction reference) {
  try {
    return run_search_unchecked(config, opt, std::move(fitness), std::move(reference));
  } catch (const std::filesystem::filesystem_error& e) {
    throw IoError(fmt::format("{}: {}", e.path1().string(), e.code().message()));
  }
}

RunSummary run_evolution(const Config& config, const RunOptions& opt, FitnessFunction fitness,
                         FitnessFunction reference) {
  try {
    return run_evolution_unchecked(config, opt, std::move(fitness), std::move(reference));
  } catch (const std::filesystem::filesystem_error& e) {
    // never an "internal error": name the path and the reason
    throw IoError(fmt::format("{}: {}", e.path1().string(), e.code().message()));
  }
}

}  // namespace animat
