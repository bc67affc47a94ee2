// Dispenser and the text of a block (dispenser.hpp).
#include "study/dispenser.hpp"

#include <algorithm>
#include <charconv>

namespace lcsim::study {

std::optional<std::size_t> Dispenser::next() {
  if (next_ >= todo_.size()) return std::nullopt;
  return todo_[next_++];
}

std::vector<Range> Dispenser::block(int ranks) {
  const std::size_t size =
      std::max<std::size_t>(1, remaining() / (4 * static_cast<std::size_t>(std::max(ranks, 1))));
  const std::size_t end = std::min(todo_.size(), next_ + size);
  std::vector<Range> ranges;
  for (; next_ < end; ++next_) {
    const std::size_t i = todo_[next_];
    if (!ranges.empty() && ranges.back().first + ranges.back().count == i)
      ++ranges.back().count;
    else
      ranges.push_back({i, 1});
  }
  return ranges;
}

std::string encode_ranges(const std::vector<Range>& ranges) {
  std::string text;
  for (const Range& r : ranges) {
    if (!text.empty()) text += ' ';
    text += std::to_string(r.first) + ' ' + std::to_string(r.count);
  }
  return text;
}

std::optional<std::vector<Range>> decode_ranges(std::string_view text) {
  std::vector<std::size_t> numbers;
  const char* p = text.data();
  const char* const end = text.data() + text.size();
  while (p < end) {
    if (!numbers.empty() && *p++ != ' ') return std::nullopt;
    std::size_t n = 0;
    const auto [q, ec] = std::from_chars(p, end, n);
    if (ec != std::errc() || q == p) return std::nullopt;
    numbers.push_back(n);
    p = q;
  }
  if (numbers.size() % 2 != 0) return std::nullopt;
  std::vector<Range> ranges;
  for (std::size_t k = 0; k < numbers.size(); k += 2) {
    if (numbers[k + 1] == 0) return std::nullopt;
    ranges.push_back({numbers[k], numbers[k + 1]});
  }
  return ranges;
}

}  // namespace lcsim::study
