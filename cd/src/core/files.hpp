// Run outputs that do not depend on the dimension: the output folder's
// checks, atomic file writes and the time series (series.csv). Every file is
// written to a temporary name and renamed into place, so a reader (or a
// killed run) never sees a half-written file.
#pragma once
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace cd {

struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A write that failed while the run went on (disk full, a file made
// unwritable, an I/O error): not bad input, and reported as such (cdsim
// exits 4). The message says "could not write" and names the file and the
// system's reason.
struct WriteError : OutputError {
  using OutputError::OutputError;
};

// Another process holds the output folder (cdsim exits 6): the message names
// the folder and the other process.
struct FolderBusy : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The output folder was removed, or replaced by another of the same name (a
// new run's), while the run wrote into it (FolderLock::check_unchanged):
// the run writes nothing more (cdsim exits 4, as for a write that failed).
struct FolderGone : WriteError {
  using WriteError::WriteError;
};

// One writer per output folder: an advisory write lock (fcntl) on
// DIR/.cdsim.lock, an empty file created once and left in place, and a lock
// (flock) on the folder itself, which holds if the lock file is removed,
// both held while this object lives. The kernel drops it when the process ends, however it
// ends (kill -9 too), so no stale lock survives a crash. A second cdsim on
// the folder throws FolderBusy naming it and the holder's pid. On a file
// system without locks (some network mounts) it warns and runs unguarded.
//
// The lock guards the folder it was taken in, not its name: a folder
// removed (rm -rf of a stopping run's outputs) and made again by another run
// is another folder, with its own lock. The files are written by path
// (series.csv reopened at each row, the others renamed into place), so
// before each write the writer calls check_unchanged(): the folder's
// identity (device, inode) taken here against what the name now points to.
// The folder is held open meanwhile, so that its inode number cannot be
// given to a folder made after it is removed.
class FolderLock {
 public:
  explicit FolderLock(const std::string& dir);
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;
  ~FolderLock();

  // Throws FolderGone naming the folder unless `dir` is still the folder
  // this lock was taken in (WriteError if it cannot be looked up at all).
  void check_unchanged() const;

 private:
  std::string dir_;
  int dir_fd_ = -1;  // the folder itself (O_PATH): its identity, pinned
  unsigned long long dev_ = 0, ino_ = 0;
  int fd_ = -1;      // DIR/.cdsim.lock, locked
  int folder_fd_ = -1;  // the folder, flock-ed: holds even if the lock file is removed
  void lock_folder(const std::string& dir, const std::string& path);
};

// Throws OutputError naming the folder if it cannot be created or written.
// Creates nothing: it checks the nearest existing ancestor.
void check_output_dir(const std::string& dir);

// The temporary name of `path` for this process, and the rename that puts a
// complete temporary file into place (removing it and throwing OutputError
// if the rename fails): the two halves of an atomic write.
std::string tmp_name(const std::string& path);
void rename_into_place(const std::string& tmp, const std::string& path);

// Writes `text` to `path` atomically (temporary file, then rename). Throws
// WriteError if any part fails, removing the temporary file: `path` is
// then as it was.
void write_file_atomic(const std::string& path, const std::string& text);

// series.csv: one row per output interval, columns named by the first row.
// Rows are written whole: a flush that fails part-way (disk full) cuts the
// file back to its length before it and throws WriteError.
// A value as series.csv writes it (integers whole, others to 10 significant
// digits): what a reader of the file gets back, exactly. The stop rule of
// core/settle.hpp decides on these, so that a resumed run, which reads the
// rows back, decides as the run never stopped did.
std::string series_text(double v);
double as_written(double v);

class Series {
 public:
  explicit Series(const std::string& path);
  // Continues a file that already holds the header `names` and earlier rows
  // (a restart): nothing is truncated and no header is written again.
  Series(const std::string& path, std::vector<std::string> names)
      : path_(path), names_(std::move(names)) {}
  void row(const std::vector<std::pair<std::string, double>>& cols);
  void flush();

 private:
  std::string path_;
  std::vector<std::string> names_;
  std::string buf_;
};

}  // namespace cd
