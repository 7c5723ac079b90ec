#include "files.hpp"
#include "printable.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <fmt/format.h>

namespace cd {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void write_failed(const std::string& path, int err) {
  throw WriteError(fmt::format("could not write '{}': {}", path, std::strerror(err)));
}

// Writes all of `text` to fd (write may write less than asked); false with
// errno set on failure.
bool write_all(int fd, std::string_view text) {
  while (!text.empty()) {
    const ssize_t n = ::write(fd, text.data(), text.size());
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    text.remove_prefix(static_cast<std::size_t>(n));
  }
  return true;
}

}  // namespace

// Unique per process, so two runs writing into one folder do not collide.
std::string tmp_name(const std::string& path) {
  return path + ".tmp." + std::to_string(::getpid());
}

void rename_into_place(const std::string& tmp, const std::string& path) {
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw WriteError(fmt::format("could not write '{}': {}", path, ec.message()));
  }
}

void check_output_dir(const std::string& dir) {
  const fs::path p = fs::absolute(fs::path(dir.empty() ? "." : dir)).lexically_normal();
  // The name on one line: printable() keeps newlines and tabs, a name shows them too.
  std::string shown;
  for (const char c : printable(dir)) shown += c == '\n' ? "\\x0A" : c == '\t' ? "\\x09" : std::string(1, c);
  auto fail = [&](const std::string& why) {
    throw OutputError(fmt::format("output folder '{}' {}", shown, why));
  };
  // A newline or another control character in the name would break the
  // run's log lines and the campaign scripts that list folders.
  for (const char c : dir)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F)
      fail(fmt::format("has a control character (\\x{:02X}) in its name: give a name without one",
                       static_cast<unsigned char>(c)));
  std::error_code ec;
  // status() reports not_found for ENOENT and ENOTDIR alike, so a path below
  // a regular file walks up to that file and fails there.
  if (fs::exists(fs::status(p, ec))) {
    if (!fs::is_directory(p, ec)) fail("exists and is not a folder");
    if (::access(p.c_str(), W_OK | X_OK) != 0) fail("is not writable");
    return;
  }
  fs::path a = p.has_filename() ? p.parent_path() : p.parent_path().parent_path();
  while (!fs::exists(fs::status(a, ec)) && a != a.root_path()) a = a.parent_path();
  if (!fs::is_directory(a, ec))
    fail(fmt::format("cannot be created: '{}' is not a folder", a.string()));
  if (::access(a.c_str(), W_OK | X_OK) != 0)
    fail(fmt::format("cannot be created: '{}' is not writable", a.string()));
}

void write_file_atomic(const std::string& path, const std::string& text) {
  const std::string tmp = tmp_name(path);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) write_failed(path, errno);
  const bool ok = write_all(fd, text);
  const int err = errno;
  if (::close(fd) != 0 || !ok) {
    const int e = ok ? errno : err;
    ::unlink(tmp.c_str());
    write_failed(path, e);
  }
  rename_into_place(tmp, path);
}

FolderLock::FolderLock(const std::string& dir) : dir_(dir) {
  // The folder first, then its lock file through it: the identity and the
  // lock are of one folder even if the name changes between the two. O_PATH
  // needs no read permission (the folder's checks ask for write and search).
#ifdef O_PATH
  constexpr int kDirFlags = O_PATH | O_DIRECTORY | O_CLOEXEC;
#else
  constexpr int kDirFlags = O_RDONLY | O_DIRECTORY | O_CLOEXEC;
#endif
  dir_fd_ = ::open(dir.c_str(), kDirFlags);
  if (dir_fd_ < 0) write_failed(dir, errno);
  struct stat st {};
  if (::fstat(dir_fd_, &st) != 0) {
    const int err = errno;
    ::close(dir_fd_);
    write_failed(dir, err);
  }
  dev_ = st.st_dev;
  ino_ = st.st_ino;
  const std::string path = (fs::path(dir) / ".cdsim.lock").string();
  fd_ = ::openat(dir_fd_, ".cdsim.lock", O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    const int err = errno;
    ::close(dir_fd_);
    write_failed(path, err);
  }
  struct flock l {};
  l.l_type = F_WRLCK;
  l.l_whence = SEEK_SET;  // the whole file (l_start = l_len = 0)
  if (::fcntl(fd_, F_SETLK, &l) == 0) {
    lock_folder(dir, path);
    return;
  }
  const int err = errno;
  if (err == EACCES || err == EAGAIN) {
    struct flock q {};
    q.l_type = F_WRLCK;
    q.l_whence = SEEK_SET;
    std::string who = "another cdsim";
    if (::fcntl(fd_, F_GETLK, &q) == 0 && q.l_type != F_UNLCK && q.l_pid > 0)
      who += fmt::format(" (pid {})", q.l_pid);
    ::close(fd_);
    ::close(dir_fd_);
    fd_ = dir_fd_ = -1;
    throw FolderBusy(fmt::format("output folder '{}' is being written by {}, which holds its lock '{}'; "
                                 "wait for it to end, or choose another --out", dir, who, path));
  }
  std::fprintf(stderr, "cdsim: warning: cannot lock '%s' (%s): nothing stops a second cdsim from writing "
               "into this folder\n", path.c_str(), std::strerror(err));
}

// The folder itself locked too (flock, a lock of its own kind): the lock
// file can be removed while the run holds it, and a second cdsim would then
// create and lock a new one; the folder cannot be replaced under the run
// (check_unchanged), so its lock stays the one taken.
void FolderLock::lock_folder(const std::string& dir, const std::string& path) {
  folder_fd_ = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (folder_fd_ >= 0 && ::flock(folder_fd_, LOCK_EX | LOCK_NB) == 0) return;
  const int err = errno;
  if (folder_fd_ >= 0 && (err == EWOULDBLOCK || err == EAGAIN)) {
    ::close(folder_fd_);
    ::close(fd_);
    ::close(dir_fd_);
    folder_fd_ = fd_ = dir_fd_ = -1;
    throw FolderBusy(fmt::format("output folder '{}' is being written by another cdsim, which holds the folder's "
                                 "lock (its lock file '{}' was removed under it); wait for it to end, or choose "
                                 "another --out", dir, path));
  }
  std::fprintf(stderr, "cdsim: warning: cannot lock the folder '%s' itself (%s): a second cdsim could write into "
               "it if its lock file were removed\n", dir.c_str(), std::strerror(err));
}

FolderLock::~FolderLock() {
  if (folder_fd_ >= 0) ::close(folder_fd_);
  if (fd_ >= 0) ::close(fd_);  // releases the lock
  if (dir_fd_ >= 0) ::close(dir_fd_);
}

void FolderLock::check_unchanged() const {
  struct stat st {};
  if (::stat(dir_.c_str(), &st) != 0) {
    if (errno != ENOENT && errno != ENOTDIR) write_failed(dir_, errno);
  } else if (st.st_dev == dev_ && st.st_ino == ino_) {
    return;
  }
  throw FolderGone(fmt::format("output folder '{}' was removed or replaced while the run was writing; "
                               "nothing written", dir_));
}

// ---------------------------------------------------------------------------
// Series

// The file is truncated here, so a rerun into the same folder does not append
// to an old series; the header goes out with the first flush.
Series::Series(const std::string& path) : path_(path) {
  const int fd = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) write_failed(path_, errno);
  ::close(fd);
}

std::string series_text(double v) {
  // Counts (step, contacts) print as integers; 2^53 bounds exact integers.
  if (v == std::trunc(v) && std::abs(v) < 9007199254740992.0) return fmt::format("{:.0f}", v);
  return fmt::format("{:.10g}", v);
}

double as_written(double v) { return std::strtod(series_text(v).c_str(), nullptr); }

void Series::row(const std::vector<std::pair<std::string, double>>& cols) {
  if (names_.empty()) {
    if (cols.empty()) throw std::logic_error("Series::row: no columns");
    for (std::size_t c = 0; c < cols.size(); ++c) {
      names_.push_back(cols[c].first);
      buf_ += (c ? "," : "") + cols[c].first;
    }
    buf_ += '\n';
  } else {
    bool same = cols.size() == names_.size();
    for (std::size_t c = 0; same && c < cols.size(); ++c) same = cols[c].first == names_[c];
    if (!same)
      throw std::logic_error(fmt::format("Series::row: columns differ from the header of '{}'", path_));
  }
  for (std::size_t c = 0; c < cols.size(); ++c) {
    const double v = cols[c].second;
    if (c) buf_ += ',';
    buf_ += series_text(v);
  }
  buf_ += '\n';
}

void Series::flush() {
  if (buf_.empty()) return;
  const int fd = ::open(path_.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
  if (fd < 0) write_failed(path_, errno);
  struct stat st {};
  const bool sized = ::fstat(fd, &st) == 0;
  if (!write_all(fd, buf_)) {
    // No half row: the file goes back to its last whole row.
    const int err = errno;
    if (sized) {
      const int r = ::ftruncate(fd, st.st_size);  // if this fails too, a resume cuts the row off
      (void)r;
    }
    ::close(fd);
    write_failed(path_, err);
  }
  if (::close(fd) != 0) write_failed(path_, errno);
  buf_.clear();
}

}  // namespace cd
