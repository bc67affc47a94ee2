// Running a study over MPI ranks. Rank 0 opens the journal, hands out the
// indices of the runs it lacks one at a time on request (dynamic balancing),
// receives each worker's rows (encode_row) and writes the journal and the
// table. Every rank computes, rank 0 on a second thread: only rank 0's main
// thread calls MPI (MPI_THREAD_FUNNELED).
//
// Messages: a worker sends kRequestsAhead kRequest at the start and a kRow after each
// run; rank 0 answers every message with one kIndex (a run index, or kStop
// when none is left), so a worker always has its next index waiting while it
// computes. Both sides poll with short sleeps (MPI_Iprobe, MPI_Test) rather
// than block in MPI_Recv, which spins a core in OpenMPI.
#include <mpi.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <exception>
#include <lcsim/io/io.hpp>
#include <lcsim/study/execute.hpp>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>

#include "study/collector.hpp"

namespace lcsim::study {

namespace {

constexpr int kRequest = 1, kRow = 2, kIndex = 3;
constexpr std::uint64_t kStop = ~std::uint64_t{0};
constexpr int kRequestsAhead = 3;
// Rank 0's MPI loop sleeps this long when idle, doubling up to the maximum
// while nothing comes (a worker holds kRequestsAhead - 1 indices in reserve,
// so a late answer rarely stalls it).
constexpr unsigned kMinIdleMicroseconds = 50, kMaxIdleMicroseconds = 1000;

// MPI_Init_thread on construction, MPI_Finalize on destruction (also when an
// exception leaves run_study_mpi).
struct MpiSession {
  MpiSession() {
    int provided = 0;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
  }
  ~MpiSession() { MPI_Finalize(); }
  int rank = 0, size = 1;
};

void send_index(std::uint64_t i, int to) {
  MPI_Send(&i, 1, MPI_UINT64_T, to, kIndex, MPI_COMM_WORLD);
}

// The next index from rank 0. Polled with a short sleep rather than a
// blocking MPI_Recv, which spins a core in OpenMPI: a worker that waits
// leaves the core to the ranks that compute.
std::uint64_t receive_index() {
  std::uint64_t i = 0;
  MPI_Request request;
  MPI_Irecv(&i, 1, MPI_UINT64_T, 0, kIndex, MPI_COMM_WORLD, &request);
  for (int done = 0;;) {
    MPI_Test(&request, &done, MPI_STATUS_IGNORE);
    if (done) return i;
    ::usleep(20);
  }
}

// A worker rank: runs indices until told to stop.
void worker(const Study& s) {
  int go = 0;
  MPI_Bcast(&go, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (!go) return;  // rank 0 could not start (it reports why)
  for (int r = 0; r < kRequestsAhead; ++r)
    MPI_Send(nullptr, 0, MPI_CHAR, 0, kRequest, MPI_COMM_WORLD);
  int outstanding = kRequestsAhead;
  while (outstanding > 0) {
    const std::uint64_t i = receive_index();
    --outstanding;
    if (i == kStop) continue;
    const std::string row = encode_row(run_one(s, static_cast<std::size_t>(i)));
    MPI_Send(row.data(), static_cast<int>(row.size()), MPI_CHAR, 0, kRow, MPI_COMM_WORLD);
    ++outstanding;
  }
}

// Rank 0's side: the indices left, shared by the local compute thread and
// the MPI loop.
class Dispenser {
 public:
  explicit Dispenser(const std::vector<std::size_t>& todo) : todo_(todo) {}
  std::optional<std::size_t> next() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (next_ >= todo_.size()) return std::nullopt;
    return todo_[next_++];
  }
  bool exhausted() {
    std::lock_guard<std::mutex> lock(mutex_);
    return next_ >= todo_.size();
  }
  void stop() {
    std::lock_guard<std::mutex> lock(mutex_);
    next_ = todo_.size();
  }

 private:
  const std::vector<std::size_t>& todo_;
  std::size_t next_ = 0;
  std::mutex mutex_;
};

// The first error of either thread of rank 0 (a journal that cannot be
// written, a malformed message); the other stops handing out work, the
// workers are still answered so that every rank ends.
struct FirstError {
  void set(std::exception_ptr e) {
    std::lock_guard<std::mutex> lock(mutex);
    if (!error) error = e;
  }
  std::exception_ptr error;
  std::mutex mutex;
};

void receive(Collector& c, const MPI_Status& st, std::string& buffer, FirstError& err,
             Dispenser& d) {
  int n = 0;
  MPI_Get_count(&st, MPI_CHAR, &n);
  buffer.resize(static_cast<std::size_t>(n));
  MPI_Recv(buffer.data(), n, MPI_CHAR, st.MPI_SOURCE, st.MPI_TAG, MPI_COMM_WORLD,
           MPI_STATUS_IGNORE);
  if (st.MPI_TAG != kRow) return;
  try {
    const auto row = decode_row(buffer);
    if (!row)
      throw std::runtime_error("study: a malformed row from MPI rank " +
                               std::to_string(st.MPI_SOURCE));
    c.add(*row);
  } catch (...) {
    err.set(std::current_exception());
    d.stop();
  }
}

void serve(const Study& s, Collector& c, int size) {
  Dispenser d(c.todo());
  FirstError err;
  std::thread local([&] {
    try {
      while (const auto i = d.next()) c.add(run_one(s, *i));
    } catch (...) {
      err.set(std::current_exception());
      d.stop();
    }
  });
  long handed = 0, rows = 0, requests = 0;
  const long workers = size - 1;
  std::string buffer;
  unsigned idle_us = kMinIdleMicroseconds;
  // Every worker message (its requests, one row per index handed out) is
  // received and answered before the loop ends.
  while (!(requests == kRequestsAhead * workers && rows == handed && d.exhausted())) {
    int flag = 0;
    MPI_Status st;
    MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &st);
    if (!flag) {
      ::usleep(idle_us);
      idle_us = std::min(2 * idle_us, kMaxIdleMicroseconds);
      continue;
    }
    idle_us = kMinIdleMicroseconds;
    receive(c, st, buffer, err, d);
    (st.MPI_TAG == kRow ? rows : requests) += 1;
    const auto i = d.next();
    send_index(i ? static_cast<std::uint64_t>(*i) : kStop, st.MPI_SOURCE);
    handed += i.has_value();
  }
  local.join();
  if (err.error) std::rethrow_exception(err.error);
}

}  // namespace

Summary run_study_mpi(const Study& s, const ExecOptions& opt) {
  MpiSession mpi;
  if (mpi.rank != 0) {
    worker(s);
    Summary sum;
    sum.writer = false;
    return sum;
  }
  std::optional<Collector> c;
  int go = 0;
  try {
    c.emplace(s, opt);
    go = 1;
  } catch (...) {
    MPI_Bcast(&go, 1, MPI_INT, 0, MPI_COMM_WORLD);
    throw;
  }
  MPI_Bcast(&go, 1, MPI_INT, 0, MPI_COMM_WORLD);
  serve(s, *c, mpi.size);
  return c->finish();
}

}  // namespace lcsim::study
