// Level files on disk: reading with a size check first, and atomic writes
// (temp file in the same folder, fsync, rename, fsync the folder) so a failed
// or killed save leaves the previous file intact.

#include "stepwise/scene_io.hpp"

#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>
#include <sstream>
#include <system_error>

#include <fcntl.h>
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

Result<void> writeFileAtomically(const fs::path& path, std::string_view bytes) {
    const std::string name = path.string();
    const fs::path folder = path.has_parent_path() ? path.parent_path() : fs::path(".");
    // Hidden temporary next to the target, so rename() stays on one filesystem.
    std::string tmpName = ".";
    tmpName += path.filename().string();
    tmpName += ".tmp-XXXXXX";
    std::string tmpl = (folder / tmpName).string();
    const int fd = ::mkstemp(tmpl.data());
    if (fd < 0) return Error{name + ": error: cannot write: " + std::strerror(errno)};
    const std::string tmpPath = tmpl;
    auto fail = [&](const char* what, int err) -> Result<void> {
        ::close(fd);
        ::unlink(tmpPath.c_str());
        return Error{name + ": error: " + what + ": " + std::strerror(err)};
    };
    // Keep an existing file's permissions; a new file gets 0666 less umask
    // (mkstemp makes 0600).
    struct stat existing {};
    mode_t mode;
    if (::stat(name.c_str(), &existing) == 0) {
        mode = existing.st_mode & 07777;
    } else {
        const mode_t mask = ::umask(0);
        ::umask(mask);
        mode = 0666 & ~mask;
    }
    if (::fchmod(fd, mode) != 0) return fail("cannot set permissions", errno);
    std::size_t written = 0;
    while (written < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
        if (n < 0) {
            if (errno == EINTR) continue;
            return fail("write failed", errno);
        }
        written += std::size_t(n);
    }
    if (::fsync(fd) != 0) return fail("fsync failed", errno);
    if (::close(fd) != 0) {
        const int err = errno;
        ::unlink(tmpPath.c_str());
        return Error{name + ": error: close failed: " + std::strerror(err)};
    }
    if (::rename(tmpPath.c_str(), name.c_str()) != 0) {
        const int err = errno;
        ::unlink(tmpPath.c_str());
        return Error{name + ": error: cannot replace the file: " + std::strerror(err)};
    }
    // Make the rename itself durable.
    const int dirFd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY);
    if (dirFd >= 0) {
        ::fsync(dirFd);
        ::close(dirFd);
    }
    return {};
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
    const std::string prefix = "." + path.filename().string() + ".tmp-";
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
    if (std::string problem = checkSceneRelations(scene); !problem.empty())
        return Error{path.string() + ": error: not saved, the scene is invalid: " + problem};
    Result<void> written = writeFileAtomically(path, sceneToJsonText(scene));
    if (written) removeStaleTemporaries(path);
    return written;
}

} // namespace stepwise
