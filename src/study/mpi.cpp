// Running a study over MPI ranks. Rank 0 opens the journal and hands out the
// runs it lacks (Dispenser: to the workers in blocks by guided
// self-scheduling, to itself one at a time). Every rank computes, rank 0 on
// its main thread: it answers the workers' messages between its own runs (and
// a second thread, asleep otherwise, during one of its runs that lasts: see
// Server::Watch), so that no service thread competes for its core.
// Workers send their finished rows (encode_row, one a line) to rank 0, which
// appends them to the journal and writes the table.
//
// Messages, all text:
//   rank 0 -> worker, kBlock: a block (encode_ranges); empty: none is left.
//   worker -> rank 0, kRequest: the rows finished since its last message,
//     and a request for the next block; kRows: rows only, sent whenever the
//     worker has held rows for kFlushSeconds; kDone: its last rows.
// Rank 0 sends every worker a block at the start; a worker asks for the next
// one when half of its block (or kKeepAhead runs) is left, so that the
// answer (given after rank 0's current run, or within kWatchPeriod) is there
// before it runs out. Nobody blocks in an MPI call, which spins a core in
// OpenMPI: a rank with nothing to do polls with sleeps.
#include <mpi.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <exception>
#include <lcsim/study/execute.hpp>
#include <list>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>

#include "study/collector.hpp"
#include "study/dispenser.hpp"
#include "study/journal.hpp"

namespace lcsim::study {

namespace {

constexpr int kBlock = 1, kRequest = 2, kRows = 3, kDone = 4;
// A killed study loses the runs in progress and at most this much of each
// worker's finished work besides.
constexpr double kFlushSeconds = 0.1;
// A worker asks for its next block when half of its block is left, or this
// many runs (the last blocks are single runs, and rank 0 answers only after
// its current run, which may be slower than the worker's).
constexpr std::size_t kKeepAhead = 4;
// A rank with nothing to do polls after this long, doubling up to the
// maximum while nothing comes.
constexpr unsigned kMinSleepMicroseconds = 20, kMaxSleepMicroseconds = 1000;
constexpr std::chrono::milliseconds kWatchPeriod{10};

using Clock = std::chrono::steady_clock;

// MPI_Init on construction, MPI_Finalize on destruction (also when an
// exception leaves run_study_mpi).
struct MpiSession {
  MpiSession() {
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &threads);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
  }
  ~MpiSession() { MPI_Finalize(); }
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  int rank = 0, size = 1, threads = MPI_THREAD_SINGLE;
};

class Backoff {
 public:
  void reset() { us_ = kMinSleepMicroseconds; }
  void sleep() {
    ::usleep(us_);
    us_ = std::min(2 * us_, kMaxSleepMicroseconds);
  }

 private:
  unsigned us_ = kMinSleepMicroseconds;
};

std::optional<MPI_Status> probe(int source, int tag) {
  int flag = 0;
  MPI_Status st;
  MPI_Iprobe(source, tag, MPI_COMM_WORLD, &flag, &st);
  if (!flag) return std::nullopt;
  return st;
}

MPI_Status wait_for(int source, int tag) {
  for (Backoff b;; b.sleep())
    if (const auto st = probe(source, tag)) return *st;
}

std::string receive(const MPI_Status& st) {
  int n = 0;
  MPI_Get_count(&st, MPI_CHAR, &n);
  std::string text(static_cast<std::size_t>(n), '\0');
  MPI_Recv(text.data(), n, MPI_CHAR, st.MPI_SOURCE, st.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  return text;
}

// Sends in flight: the sender goes on computing while a message travels (a
// large one waits for the receiver to take it).
class Outbox {
 public:
  void send(std::string text, int tag, int to) {
    auto& [buffer, request] = sends_.emplace_back(std::move(text), MPI_REQUEST_NULL);
    MPI_Isend(buffer.data(), static_cast<int>(buffer.size()), MPI_CHAR, to, tag, MPI_COMM_WORLD,
              &request);
  }
  void test() {
    std::erase_if(sends_, [](auto& s) {
      int done = 0;
      MPI_Test(&s.second, &done, MPI_STATUS_IGNORE);
      return done != 0;
    });
  }
  void drain() {
    for (Backoff b; test(), !sends_.empty(); b.sleep()) {
    }
  }

 private:
  std::list<std::pair<std::string, MPI_Request>> sends_;
};

// A worker rank: runs the blocks rank 0 sends until it sends an empty one.
class Worker {
 public:
  explicit Worker(const Study& s) : s_(s) {}
  void run() {
    take(receive(wait_for(0, kBlock)));
    while (!queue_.empty() || !stopped_) {
      if (!asked_ && !stopped_ && queue_.size() <= std::max(half_, kKeepAhead)) send(kRequest);
      if (queue_.empty()) {
        take(receive(wait_for(0, kBlock)));
        continue;
      }
      const std::size_t i = queue_.front();
      queue_.pop_front();
      rows_ += encode_row(run_one(s_, i)) + '\n';
      if (const auto st = probe(0, kBlock)) take(receive(*st));
      if (std::chrono::duration<double>(Clock::now() - last_sent_).count() >= kFlushSeconds)
        send(kRows);
      out_.test();
    }
    send(kDone);
    out_.drain();
  }

 private:
  void send(int tag) {
    out_.send(std::move(rows_), tag, 0);
    rows_.clear();
    last_sent_ = Clock::now();
    asked_ = asked_ || tag == kRequest;
  }
  void take(const std::string& text) {
    const auto ranges = decode_ranges(text);
    if (!ranges) throw std::runtime_error("study: a malformed block from MPI rank 0");
    asked_ = false;
    stopped_ = ranges->empty();
    std::size_t n = 0;
    for (const Range& r : *ranges)
      for (std::size_t k = 0; k < r.count; ++k, ++n) queue_.push_back(r.first + k);
    half_ = n / 2;
  }
  const Study& s_;
  std::deque<std::size_t> queue_;
  std::size_t half_ = 0;
  bool asked_ = false, stopped_ = false;
  std::string rows_;
  Clock::time_point last_sent_ = Clock::now();
  Outbox out_;
};

// Rank 0: computes runs and serves the workers between them until every
// run is handed out and every worker is done. The first error (a journal
// that cannot be written, a malformed message) stops the hand-out; the
// workers are still answered so that every rank ends, then it is thrown.
class Server {
 public:
  Server(const Study& s, Collector& c, int size, bool watch)
      : s_(s), c_(c), d_(c.todo()), size_(size), watch_(watch) {}
  void run() {
    std::unique_lock lock(m_);
    for (int w = 1; w < size_; ++w) reply(w);
    Watch watch(*this, lock);
    for (Backoff idle;;) {
      const bool served = serve();
      if (const auto i = d_.next()) {
        ++runs_started_;
        running_ = true;
        lock.unlock();
        const Row row = run_one(s_, *i);
        lock.lock();
        running_ = false;
        add(row);
      } else if (done_ == size_ - 1) {
        break;
      } else {
        if (served) idle.reset();
        lock.unlock();
        idle.sleep();
        lock.lock();
      }
    }
    lock.unlock();
    watch.stop();
    out_.drain();
    if (error_) std::rethrow_exception(error_);
  }

 private:
  // While one of rank 0's own runs lasts longer than kWatchPeriod, a second
  // thread serves the workers every kWatchPeriod, so that a long run does not
  // leave them waiting for their next block. It sleeps otherwise (a hundred
  // wake-ups a second). MPI_THREAD_SERIALIZED: both threads call MPI only
  // holding m_, which the main thread releases during its runs.
  class Watch {
   public:
    Watch(Server& s, std::unique_lock<std::mutex>& lock) : s_(s), lock_(lock) {
      if (s.watch_) thread_ = std::thread([this] { watch(); });
    }
    ~Watch() { stop(); }
    Watch(const Watch&) = delete;
    Watch& operator=(const Watch&) = delete;
    void stop() {
      if (!thread_.joinable()) return;
      if (!lock_.owns_lock()) lock_.lock();
      finished_ = true;
      lock_.unlock();
      woken_.notify_one();
      thread_.join();
    }

   private:
    void watch() {
      std::unique_lock lock(s_.m_);
      for (std::size_t seen = 0;;) {
        if (woken_.wait_for(lock, kWatchPeriod, [&] { return finished_; })) return;
        if (s_.running_ && s_.runs_started_ == seen) s_.serve();
        seen = s_.runs_started_;
      }
    }
    Server& s_;
    std::unique_lock<std::mutex>& lock_;
    bool finished_ = false;
    std::condition_variable woken_;
    std::thread thread_;
  };

  // Answers every message waiting; true if there was one.
  bool serve() {
    bool served = false;
    for (std::optional<MPI_Status> st; (st = probe(MPI_ANY_SOURCE, MPI_ANY_TAG)); served = true)
      handle(*st);
    out_.test();
    return served;
  }
  void reply(int to) { out_.send(encode_ranges(d_.block(size_)), kBlock, to); }
  void handle(const MPI_Status& st) {
    const std::string text = receive(st);
    for (std::size_t pos = 0, end; (end = text.find('\n', pos)) != std::string::npos;
         pos = end + 1) {
      const auto row = decode_row(std::string_view(text).substr(pos, end - pos));
      if (!row) fail("study: a malformed row from MPI rank " + std::to_string(st.MPI_SOURCE));
      if (row) add(*row);
    }
    if (st.MPI_TAG == kRequest) reply(st.MPI_SOURCE);
    done_ += st.MPI_TAG == kDone;
  }
  void add(const Row& row) {
    if (error_) return;
    try {
      c_.add(row);
    } catch (...) {
      error_ = std::current_exception();
      d_.stop();
    }
  }
  void fail(const std::string& what) {
    if (error_) return;
    error_ = std::make_exception_ptr(std::runtime_error(what));
    d_.stop();
  }
  const Study& s_;
  Collector& c_;
  Dispenser d_;
  int size_, done_ = 0;
  bool watch_, running_ = false;
  std::size_t runs_started_ = 0;
  std::exception_ptr error_;
  Outbox out_;
  std::mutex m_;
};

// Rank 0 could not start (it throws why): every worker is told to stop and
// heard from before MPI_Finalize.
void stop_workers(int size) {
  Outbox out;
  for (int w = 1; w < size; ++w) out.send(std::string(), kBlock, w);
  for (int w = 1; w < size; ++w) (void)receive(wait_for(w, kDone));
  out.drain();
}

}  // namespace

Summary run_study_mpi(const Study& s, const ExecOptions& opt) {
  MpiSession mpi;
  if (mpi.rank != 0) {
    Worker(s).run();
    Summary sum;
    sum.writer = false;
    return sum;
  }
  std::optional<Collector> c;
  try {
    c.emplace(s, opt);
  } catch (...) {
    stop_workers(mpi.size);
    throw;
  }
  Server(s, *c, mpi.size, mpi.threads >= MPI_THREAD_SERIALIZED).run();
  return c->finish();
}

}  // namespace lcsim::study
