// Level files on disk: reading with a size check first, and atomic writes
// (temp file in the same folder, fsync, rename, fsync the folder) so a failed
// or killed save leaves the previous file intact.

#include "stepwise/scene_io.hpp"

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>
#include <mutex>
#include <vector>
#include <sstream>
#include <system_error>

#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

namespace stepwise {

namespace fs = std::filesystem;

Result<Scene> loadSceneFile(const fs::path& path, const LoadLimits& limits) {
    const std::string name = path.string();
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    if (ec || !fs::exists(status)) return Error{name + ": error: no such file"};
    if (fs::is_directory(status)) return Error{name + ": error: is a directory, expected a level file"};
    // A device or pipe has no size to check against the limit, and reading
    // one may never end.
    if (!fs::is_regular_file(status))
        return Error{name + ": error: is not a regular file (a device, pipe or socket); expected a level file"};
    const std::uintmax_t size = fs::file_size(path, ec);
    if (ec) return Error{name + ": error: cannot read: " + ec.message()};
    // Checked before reading so a huge file costs nothing.
    if (size > limits.maxFileBytes)
        return Error{name + ": error: file is " + std::to_string(size) + " bytes; the limit is " +
                     std::to_string(limits.maxFileBytes) + " bytes"};
    std::ifstream in(path, std::ios::binary);
    if (!in) return Error{name + ": error: cannot open: " + std::strerror(errno)};
    std::string text(size, '\0');
    in.read(text.data(), std::streamsize(size));
    if (in.gcount() != std::streamsize(size)) return Error{name + ": error: read failed"};
    return parseScene(text, name, limits);
}

fs::path resolveOutputPath(const fs::path& path) {
    fs::path p = path;
    // Linux's own bound on a chain of links; past it (a loop) the path is
    // returned as it is and stat() says "Too many levels of symbolic links".
    for (int hops = 0; hops < 40; ++hops) {
        std::error_code ec;
        if (!fs::is_symlink(fs::symlink_status(p, ec)) || ec) return p;
        const fs::path to = fs::read_symlink(p, ec);
        if (ec) return p;
        p = to.is_absolute() ? to : (p.has_parent_path() ? p.parent_path() : fs::path(".")) / to;
    }
    return path;
}

std::string checkWritableTarget(const fs::path& given) {
    const std::string name = given.string();
    const auto cannot = [&](const std::string& why) { return name + ": error: cannot write: " + why; };
    if (name.empty()) return ": error: cannot write: no file name given";
    const fs::path path = resolveOutputPath(given);
    const fs::path folder = path.has_parent_path() ? path.parent_path() : fs::path(".");
    struct stat info {};
    if (::stat(folder.c_str(), &info) != 0) return cannot(std::strerror(errno));
    if (!S_ISDIR(info.st_mode)) return cannot(std::strerror(ENOTDIR));
    // The temporary is created in the folder and renamed there.
    if (::access(folder.c_str(), W_OK | X_OK) != 0) return cannot(std::strerror(errno));
    if (::stat(path.c_str(), &info) == 0) {
        if (S_ISDIR(info.st_mode)) return cannot(std::strerror(EISDIR));
        // A device or pipe (/dev/stdout) would be replaced by the rename,
        // not written through.
        if (!S_ISREG(info.st_mode)) return cannot("not a regular file (outputs are replaced by a rename)");
        // The rename would replace a read-only file too (it needs only the
        // folder's permission); the file's own mode says the user may not.
        if (::access(path.c_str(), W_OK) != 0) return cannot(std::strerror(errno));
    } else if (errno == ELOOP) {
        return cannot(std::strerror(ELOOP));
    }
    return {};
}

namespace {

/// The temporaries of unfinished writers, for removeUnfinishedTemporaries.
/// A signal handler walks the list without allocating or locking: nodes
/// are only ever added at the head and never freed, and a node's path is
/// read only while the node is live. Writers take and give back nodes
/// under a mutex, through a free list, so listing costs O(1) however many
/// temporaries are pending (render --frames keeps one per frame).
struct TemporaryNode {
    std::atomic<int> live{0};
    std::string path;
    TemporaryNode* next = nullptr;
};
std::atomic<TemporaryNode*> gTemporaries{nullptr};
std::mutex gTemporariesMutex;
std::vector<TemporaryNode*> gFreeTemporaries;

TemporaryNode* listTemporary(const std::string& path) {
    std::lock_guard<std::mutex> lock(gTemporariesMutex);
    TemporaryNode* node = nullptr;
    if (!gFreeTemporaries.empty()) {
        node = gFreeTemporaries.back();
        gFreeTemporaries.pop_back();
    } else {
        node = new TemporaryNode;  // kept for the life of the process
        node->next = gTemporaries.load();
        gTemporaries.store(node);
    }
    node->path = path;
    node->live.store(1);
    return node;
}

void unlistTemporary(void*& slot) {
    if (!slot) return;
    auto* node = static_cast<TemporaryNode*>(slot);
    std::lock_guard<std::mutex> lock(gTemporariesMutex);
    node->live.store(0);
    gFreeTemporaries.push_back(node);
    slot = nullptr;
}

} // namespace

void removeUnfinishedTemporaries() noexcept {
    for (TemporaryNode* node = gTemporaries.load(); node; node = node->next)
        if (node->live.load()) ::unlink(node->path.c_str());
}

Result<StreamedFileWriter> StreamedFileWriter::open(const fs::path& given) {
    if (std::string problem = checkWritableTarget(given); !problem.empty()) return Error{problem};
    // Through a link: the temporary goes beside the target and replaces it.
    const fs::path path = resolveOutputPath(given);
    StreamedFileWriter w;
    w.name_ = path.string();
    w.folder_ = path.has_parent_path() ? path.parent_path() : fs::path(".");
    // Hidden temporary next to the target, so rename() stays on one filesystem.
    std::string tmpName = ".";
    tmpName += path.filename().string();
    tmpName += ".tmp-XXXXXX";
    std::string tmpl = (w.folder_ / tmpName).string();
    // A signal whose handler removes the unfinished temporaries (the
    // command line's interrupt) must not land between mkstemp creating the
    // file and the file being listed: the handler would miss it and leave
    // it behind (one interrupted render --frames in thirty did). Blocked
    // for those two calls, it is delivered right after, with the file listed.
    sigset_t all, before;
    sigfillset(&all);
    ::pthread_sigmask(SIG_BLOCK, &all, &before);
    w.fd_ = ::mkstemp(tmpl.data());
    const int created = errno;
    if (w.fd_ >= 0) {
        w.tmpPath_ = tmpl;
        w.slot_ = listTemporary(w.tmpPath_);
    }
    ::pthread_sigmask(SIG_SETMASK, &before, nullptr);
    if (w.fd_ < 0) return Error{w.name_ + ": error: cannot write: " + std::strerror(created)};
    // Keep an existing file's permissions; a new file gets 0666 less umask
    // (mkstemp makes 0600).
    struct stat existing {};
    mode_t mode;
    if (::stat(w.name_.c_str(), &existing) == 0) {
        mode = existing.st_mode & 07777;
    } else {
        const mode_t mask = ::umask(0);
        ::umask(mask);
        mode = 0666 & ~mask;
    }
    if (::fchmod(w.fd_, mode) != 0) return Error{w.fail("cannot set permissions", errno).error()};
    return w;
}

StreamedFileWriter::StreamedFileWriter(StreamedFileWriter&& o) noexcept
    : name_(std::move(o.name_)), tmpPath_(std::move(o.tmpPath_)), folder_(std::move(o.folder_)),
      buffer_(std::move(o.buffer_)), fd_(o.fd_), finished_(o.finished_), slot_(o.slot_) {
    o.fd_ = -1;
    o.slot_ = nullptr;
    o.tmpPath_.clear();
}

StreamedFileWriter& StreamedFileWriter::operator=(StreamedFileWriter&& o) noexcept {
    if (this != &o) {
        discard();
        name_ = std::move(o.name_);
        tmpPath_ = std::move(o.tmpPath_);
        folder_ = std::move(o.folder_);
        buffer_ = std::move(o.buffer_);
        fd_ = o.fd_;
        finished_ = o.finished_;
        slot_ = o.slot_;
        o.fd_ = -1;
        o.slot_ = nullptr;
        o.tmpPath_.clear();
    }
    return *this;
}

StreamedFileWriter::~StreamedFileWriter() { discard(); }

void StreamedFileWriter::discard() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    if (!tmpPath_.empty()) ::unlink(tmpPath_.c_str());
    unlistTemporary(slot_);
    tmpPath_.clear();
    buffer_.clear();
}

Result<void> StreamedFileWriter::fail(const char* what, int err) {
    discard();
    return Error{name_ + ": error: " + what + ": " + std::strerror(err)};
}

Result<void> StreamedFileWriter::writeAll(std::string_view bytes) {
    std::size_t written = 0;
    while (written < bytes.size()) {
        const ssize_t n = ::write(fd_, bytes.data() + written, bytes.size() - written);
        if (n < 0) {
            if (errno == EINTR) continue;
            return fail("write failed", errno);
        }
        written += std::size_t(n);
    }
    return {};
}

Result<void> StreamedFileWriter::write(std::string_view bytes) {
    if (fd_ < 0) return Error{name_ + ": error: write failed: the file is closed"};
    constexpr std::size_t kBlock = 1u << 20;
    if (buffer_.size() + bytes.size() < kBlock) {
        buffer_.append(bytes);
        return {};
    }
    // A full block: write what is buffered, then `bytes` without copying
    // them (a whole level saved at once).
    if (Result<void> flushed = writeAll(buffer_); !flushed) return flushed;
    buffer_.clear();
    return writeAll(bytes);
}

Result<void> StreamedFileWriter::finish() {
    if (finished_) return {};
    if (fd_ < 0) return Error{name_ + ": error: write failed: the file is closed"};
    if (Result<void> flushed = writeAll(buffer_); !flushed) return flushed;
    buffer_.clear();
    if (::fsync(fd_) != 0) return fail("fsync failed", errno);
    const int fd = fd_;
    fd_ = -1;
    if (::close(fd) != 0) return fail("close failed", errno);
    finished_ = true;
    return {};
}

Result<void> StreamedFileWriter::commit() {
    if (Result<void> done = finish(); !done) return done;
    if (::rename(tmpPath_.c_str(), name_.c_str()) != 0) return fail("cannot replace the file", errno);
    unlistTemporary(slot_);
    tmpPath_.clear();
    // Make the rename itself durable.
    const int dirFd = ::open(folder_.c_str(), O_RDONLY | O_DIRECTORY);
    if (dirFd >= 0) {
        ::fsync(dirFd);
        ::close(dirFd);
    }
    return {};
}

Result<void> writeFileAtomically(const fs::path& path, std::string_view bytes) {
    Result<StreamedFileWriter> writer = StreamedFileWriter::open(path);
    if (!writer) return Error{writer.error()};
    if (Result<void> written = writer->write(bytes); !written) return written;
    return writer->commit();
}

namespace {

/// A save killed between mkstemp and rename (SIGKILL, power loss) leaves its
/// hidden temporary `.NAME.tmp-XXXXXX` behind; the level itself is intact
/// and no loader ever reads such a file. Each later save of the same level
/// removes the ones older than an hour. Younger ones are left alone: they
/// may belong to a save still running in another process (the editor's
/// autosave and a CLI run on the same file), and deleting that one's
/// temporary would make its rename fail. Only level saves do this, not
/// every writeFileAtomically: `render --frames` writes thousands of files
/// into one folder, and a scan per file would make that quadratic.
void removeStaleTemporaries(const fs::path& path) {
    const fs::path folder = path.has_parent_path() ? path.parent_path() : fs::path(".");
    // Appended, not "." + name + ...: GCC 12 warns falsely (-Wrestrict) on that once inlined.
    std::string prefix = ".";
    prefix.append(path.filename().string()).append(".tmp-");
    const auto now = fs::file_time_type::clock::now();
    std::error_code ec;
    for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string name = it->path().filename().string();
        if (name.size() != prefix.size() + 6 || name.compare(0, prefix.size(), prefix) != 0) continue;
        std::error_code fileEc;
        if (it->symlink_status(fileEc).type() != fs::file_type::regular) continue;
        const auto modified = it->last_write_time(fileEc);
        if (fileEc || now - modified < std::chrono::hours(1)) continue;
        fs::remove(it->path(), fileEc);  // best effort: a leftover costs only disk space
    }
}

} // namespace

Result<void> saveSceneFile(const Scene& scene, const fs::path& path) {
    if (const std::optional<Error> problem = checkSceneRelations(scene)) {
        std::string message = path.string();
        message.append(": error: not saved, the scene is invalid: ").append(problem->message);
        return Error{std::move(message)};
    }
    Result<void> written = writeFileAtomically(path, sceneToJsonText(scene));
    if (written) removeStaleTemporaries(resolveOutputPath(path));
    return written;
}

} // namespace stepwise
