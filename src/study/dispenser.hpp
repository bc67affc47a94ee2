// The runs an MPI study lacks, as rank 0 hands them out (internal to
// src/study; mpi.cpp). Rank 0 takes them one at a time for itself, a worker
// rank a block at a time by guided self-scheduling: max(1, remaining /
// (4 ranks)) of them, so that the first blocks are large (few messages) and
// the last ones single runs (a run a thousand times slower than the others
// still holds one rank only). A block travels as ranges of consecutive
// indices ("first count" pairs in decimal text): one range for a fresh
// study, a few where a resumed journal left gaps.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace lcsim::study {

struct Range {
  std::size_t first = 0, count = 0;
  bool operator==(const Range&) const = default;
};

class Dispenser {
 public:
  // `todo`: the indices to run, ascending (Collector::todo()).
  explicit Dispenser(const std::vector<std::size_t>& todo) : todo_(todo) {}
  // The next index, nullopt when none is left.
  std::optional<std::size_t> next();
  // The next block for one of `ranks` ranks, empty when none is left.
  std::vector<Range> block(int ranks);
  std::size_t remaining() const { return todo_.size() - next_; }
  // Hands out nothing more (an error on rank 0).
  void stop() { next_ = todo_.size(); }

 private:
  const std::vector<std::size_t>& todo_;
  std::size_t next_ = 0;
};

// "first count first count ...", and back (nullopt for other text).
std::string encode_ranges(const std::vector<Range>& ranges);
std::optional<std::vector<Range>> decode_ranges(std::string_view text);

}  // namespace lcsim::study
