// The journal of a study (internal to src/study): one line per finished run,
// appended whole, each line carrying its own check so that a torn last line
// (a machine that died mid-write) is recognised and dropped.
//
//   line 1:  {"journal":"lcsim-study","runs":N,"study":<fingerprint>,"version":1}\t<check>
//   then:    {"c":[cells...],"i":index,"ok":completed,"w":wall_time_s}\t<check>
//
// <check> is fingerprint() (FNV-1a 64, 16 hex digits) of the JSON before the
// tab. Rows are the encoded Row that MPI workers send to rank 0.
#pragma once

#include <chrono>
#include <cstddef>
#include <filesystem>
#include <lcsim/study/run.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace lcsim::study {

std::string encode_row(const Row& row);
// nullopt for text that is not an encoded row.
std::optional<Row> decode_row(std::string_view json);

class Journal {
 public:
  // Opens `path` for appending. A journal already there is read when
  // `resume` (its rows are returned by rows(); a torn or damaged tail is cut
  // off) and is an InputError otherwise; one of another study (fingerprint
  // or run count) is an InputError either way.
  Journal(const std::filesystem::path& path, const std::string& study_fingerprint, std::size_t runs,
          bool resume);
  ~Journal();
  Journal(const Journal&) = delete;
  Journal& operator=(const Journal&) = delete;
  // The rows found on opening (resume), at most one per index.
  const std::vector<Row>& rows() const { return found_; }
  // Appends the row's line with one write(2): a process killed at any point
  // leaves whole lines. fdatasync(2) at most once per kSyncSeconds and on
  // close: a machine that dies loses at most that much work.
  void append(const Row& row);
  void sync();
  static constexpr double kSyncSeconds = 1.0;

 private:
  void write_line(const std::string& json);
  std::string path_;
  int fd_ = -1;
  std::vector<Row> found_;
  std::chrono::steady_clock::time_point last_sync_;
};

}  // namespace lcsim::study
