// The study journal (journal.hpp).
#include "study/journal.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <lcsim/io/io.hpp>
#include <lcsim/io/text.hpp>
#include <nlohmann/json.hpp>
#include <set>

#include "study/detail.hpp"

namespace lcsim::study {

namespace {

[[noreturn]] void cannot(const std::string& path, const std::string& what, int err) {
  throw io::InputError(path + ": cannot " + what + ": " + std::strerror(err));
}

std::string header_json(const std::string& fp, std::size_t runs) {
  return nlohmann::json{{"journal", "lcsim-study"}, {"version", 1}, {"study", fp}, {"runs", runs}}
      .dump();
}

// The JSON of a line whose check holds, else nullopt.
std::optional<std::string> checked(std::string_view line) {
  const auto tab = line.rfind('\t');
  if (tab == std::string_view::npos) return std::nullopt;
  const std::string_view json = line.substr(0, tab);
  if (line.substr(tab + 1) != fingerprint(json)) return std::nullopt;
  return std::string(json);
}

}  // namespace

std::string encode_row(const Row& row) {
  return nlohmann::json{
      {"i", row.index}, {"w", row.wall_time_s}, {"ok", row.completed}, {"c", row.cells}}
      .dump();
}

std::optional<Row> decode_row(std::string_view json) {
  try {
    const auto j = nlohmann::json::parse(json);
    Row r;
    r.index = j.at("i").get<std::size_t>();
    r.wall_time_s = j.at("w").get<double>();
    r.completed = j.at("ok").get<bool>();
    r.cells = j.at("c").get<std::vector<std::string>>();
    return r;
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;
  }
}

Journal::Journal(const std::filesystem::path& path, const std::string& fp, std::size_t runs,
                 bool resume)
    : path_(path.string()), last_sync_(std::chrono::steady_clock::now()) {
  const bool exists = std::filesystem::exists(path);
  if (exists && !resume)
    throw io::InputError(path_ + ": a journal of an earlier run is here: resume = true continues " +
                         "it, or remove it to start again");
  const std::string header = header_json(fp, runs);
  std::size_t keep = 0;  // bytes of whole, checked lines
  if (exists) {
    const std::string text = io::read_file(path);
    std::set<std::size_t> seen;
    std::size_t pos = 0;
    bool first = true;
    while (pos < text.size()) {
      const auto end = text.find('\n', pos);
      if (end == std::string::npos) break;  // a torn last line
      const auto json = checked(std::string_view(text).substr(pos, end - pos));
      if (!json) break;  // damaged: this line and what follows are dropped
      if (first) {
        if (*json != header)
          throw io::InputError(path_ + ": the journal of another study (or of this file " +
                               "before an edit): remove it to start again");
        first = false;
      } else {
        const auto row = decode_row(*json);
        if (!row || row->index >= runs) break;
        if (seen.insert(row->index).second) found_.push_back(*row);
      }
      pos = end + 1;
      keep = pos;
    }
  }
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd_ < 0) cannot(path_, "open for appending", errno);
  if (::ftruncate(fd_, static_cast<off_t>(keep)) != 0) cannot(path_, "truncate", errno);
  if (keep == 0) write_line(header);
  sync();
}

Journal::~Journal() {
  if (fd_ < 0) return;
  ::fdatasync(fd_);
  ::close(fd_);
}

void Journal::write_line(const std::string& json) {
  const std::string line = json + "\t" + fingerprint(json) + "\n";
  std::size_t done = 0;
  while (done < line.size()) {
    const ssize_t n = ::write(fd_, line.data() + done, line.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) cannot(path_, "append", n < 0 ? errno : EIO);
    done += static_cast<std::size_t>(n);
  }
}

void Journal::append(const Row& row) {
  write_line(encode_row(row));
  const auto now = std::chrono::steady_clock::now();
  if (std::chrono::duration<double>(now - last_sync_).count() >= kSyncSeconds) sync();
}

void Journal::sync() {
  if (::fdatasync(fd_) != 0) cannot(path_, "sync", errno);
  last_sync_ = std::chrono::steady_clock::now();
}

}  // namespace lcsim::study
