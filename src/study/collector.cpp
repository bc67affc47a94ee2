// Collector (collector.hpp) and the table's text.
#include "study/collector.hpp"

#include <algorithm>
#include <cstdio>
#include <lcsim/io/io.hpp>
#include <lcsim/io/text.hpp>
#include <nlohmann/json.hpp>
#include <thread>

namespace lcsim::study {

namespace {

std::string journal_path(const ExecOptions& opt) { return opt.out.string() + ".journal"; }

bool is_jsonl(const std::filesystem::path& p) { return p.extension() == ".jsonl"; }

// RFC 4180 quoting where a cell needs it.
std::string csv_cell(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string q = "\"";
  for (const char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

nlohmann::json json_cell(const std::string& cell, bool text) {
  if (text) return cell;
  if (cell.empty() || cell == "inf" || cell == "-inf" || cell == "nan" || cell == "-nan")
    return nullptr;
  return nlohmann::json::parse(cell);
}

std::string seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f s", s);
  return buf;
}

}  // namespace

std::string table_text(const Study& s, const std::vector<Row>& rows, bool jsonl) {
  const std::vector<Column> cols = columns(s);
  std::string out;
  if (!jsonl) {
    for (std::size_t i = 0; i < cols.size(); ++i) out += (i ? "," : "") + csv_cell(cols[i].name);
    out += '\n';
  }
  for (const Row& r : rows) {
    if (jsonl) {
      nlohmann::ordered_json j;
      for (std::size_t i = 0; i < cols.size() && i < r.cells.size(); ++i)
        j[cols[i].name] = json_cell(r.cells[i], cols[i].text);
      out += j.dump() + "\n";
      continue;
    }
    for (std::size_t i = 0; i < r.cells.size(); ++i) out += (i ? "," : "") + csv_cell(r.cells[i]);
    out += '\n';
  }
  return out;
}

int jobs_of(const ExecOptions& opt) {
  if (opt.jobs > 0) return opt.jobs;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

Collector::Collector(const Study& s, const ExecOptions& opt)
    : study_(s), opt_(opt), start_(std::chrono::steady_clock::now()), last_progress_(start_) {
  if (opt.out.empty()) throw io::InputError("out: no output file given");
  if (opt.jobs < 0)
    throw io::InputError("jobs: must be >= 0, 0 for one per core (got " + std::to_string(opt.jobs) +
                         ")");
  const std::size_t n = run_count(s);
  journal_ = std::make_unique<Journal>(journal_path(opt), s.fingerprint, n, opt.resume);
  rows_ = journal_->rows();
  resumed_ = rows_.size();
  std::vector<char> done(n, 0);
  for (const Row& r : rows_) done[r.index] = 1;
  for (std::size_t i = 0; i < n; ++i)
    if (!done[i]) todo_.push_back(i);
}

void Collector::add(const Row& row) {
  std::lock_guard<std::mutex> lock(mutex_);
  journal_->append(row);
  rows_.push_back(row);
  ++computed_;
  progress(false);
}

void Collector::progress(bool last) {
  if (!opt_.progress) return;
  const auto now = std::chrono::steady_clock::now();
  if (!last && std::chrono::duration<double>(now - last_progress_).count() < 1.0) return;
  last_progress_ = now;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const std::size_t left = todo_.size() - computed_;
  std::string line = std::to_string(rows_.size()) + "/" + std::to_string(run_count(study_)) +
                     " runs, " + seconds(elapsed);
  if (computed_ > 0 && left > 0)
    line += ", " + seconds(elapsed / static_cast<double>(computed_) * static_cast<double>(left)) +
            " left";
  opt_.progress(line);
}

Summary Collector::finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  journal_->sync();
  progress(true);
  std::sort(rows_.begin(), rows_.end(),
            [](const Row& a, const Row& b) { return a.index < b.index; });
  io::write_file_atomic(opt_.out, table_text(study_, rows_, is_jsonl(opt_.out)));
  Summary sum;
  sum.total = run_count(study_);
  sum.resumed = resumed_;
  sum.computed = computed_;
  for (const Row& r : rows_) sum.failed += !r.completed;
  sum.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  return sum;
}

}  // namespace lcsim::study
