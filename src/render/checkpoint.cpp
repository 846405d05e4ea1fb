// Checkpoint files (see checkpoint.h). Our own small binary format rather than a library:
// the state is a few flat arrays of doubles plus strings, and the checks (digests, option
// lines, checksum) are what matters; EXR would round-trip the sums as floats only.
#include "render/checkpoint.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "core/error.h"

namespace ub {

namespace {

constexpr char kMagic[8] = {'U', 'B', 'C', 'K', 'P', 'T', '\n', '\0'};

uint64_t fnv1a(const void* data, size_t n, uint64_t h = 1469598103934665603ull) {
    const unsigned char* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) {
        h ^= p[i];
        h *= 1099511628211ull;
    }
    return h;
}

std::string hex64(uint64_t v) {
    char b[17];
    std::snprintf(b, sizeof(b), "%016llx", static_cast<unsigned long long>(v));
    return b;
}

class Writer {
  public:
    void bytes(const void* p, size_t n) {
        const char* c = static_cast<const char*>(p);
        buf_.insert(buf_.end(), c, c + n);
    }
    template <class T>
    void pod(const T& v) {
        bytes(&v, sizeof(T));
    }
    void str(const std::string& s) {
        pod(uint32_t(s.size()));
        bytes(s.data(), s.size());
    }
    void doubles(const std::vector<double>& v) {
        pod(uint64_t(v.size()));
        bytes(v.data(), v.size() * sizeof(double));
    }
    std::vector<char>& data() { return buf_; }

  private:
    std::vector<char> buf_;
};

class Reader {
  public:
    Reader(const std::vector<char>& d, const std::string& file) : d_(d), file_(file) {}
    void bytes(void* p, size_t n) {
        if (n > d_.size() - at_) fail("the file is truncated");
        std::memcpy(p, d_.data() + at_, n);
        at_ += n;
    }
    template <class T>
    T pod() {
        T v;
        bytes(&v, sizeof(T));
        return v;
    }
    std::string str() {
        const uint32_t n = pod<uint32_t>();
        if (n > d_.size() - at_) fail("the file is truncated");
        std::string s(d_.data() + at_, n);
        at_ += n;
        return s;
    }
    std::vector<double> doubles(size_t expected) {
        const uint64_t n = pod<uint64_t>();
        if (n != expected)
            fail("an array has " + std::to_string(n) + " values, expected " +
                 std::to_string(expected));
        std::vector<double> v(n);
        bytes(v.data(), n * sizeof(double));
        return v;
    }
    [[noreturn]] void fail(const std::string& what) const {
        throw InputError(file_, "checkpoint: " + what + " (at byte " + std::to_string(at_) + ")");
    }

  private:
    const std::vector<char>& d_;
    std::string file_;
    size_t at_ = 0;
};

std::map<std::string, std::string> optionLines(const std::string& text) {
    std::map<std::string, std::string> out;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) {
        const size_t eq = line.find('=');
        if (eq != std::string::npos) out[line.substr(0, eq)] = line.substr(eq + 1);
    }
    return out;
}

}  // namespace

std::string digestFile(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) throw InputError(path, "cannot read the file to digest it");
    std::vector<char> buf(1 << 16);
    uint64_t h = 1469598103934665603ull;
    while (f) {
        f.read(buf.data(), std::streamsize(buf.size()));
        h = fnv1a(buf.data(), size_t(f.gcount()), h);
    }
    return hex64(h);
}

void writeCheckpoint(const std::string& path, const CheckpointHeader& header,
                     const ProgressiveState& s, long long failAfterBytesForTest) {
    Writer w;
    w.bytes(kMagic, sizeof(kMagic));
    w.pod(kCheckpointFormat);
    w.str(header.version);
    w.str(header.sceneDigest);
    w.str(header.options);
    w.pod(header.width);
    w.pod(header.height);
    w.pod(int32_t(s.iterations));
    w.pod(s.seconds);
    w.pod(uint32_t(s.layers.size()));
    for (size_t i = 0; i < s.layers.size(); ++i) {
        w.str(s.layerNames[i]);
        w.pod(uint64_t(s.layerRejected[i]));
        w.doubles(s.layers[i]);
    }
    w.pod(uint64_t(s.filmRejected));
    w.doubles(s.film);
    w.pod(uint8_t(s.hasVariance ? 1 : 0));
    if (s.hasVariance) {
        w.doubles(s.varianceMean);
        w.doubles(s.varianceM2);
    }
    w.pod(uint32_t(s.rejected.size()));
    for (const auto& r : s.rejected) {
        w.str(r.first);
        w.pod(uint64_t(r.second));
    }
    w.pod(fnv1a(w.data().data(), w.data().size()));

    namespace fs = std::filesystem;
    const fs::path target(path);
    fs::path dir = target.parent_path();
    if (dir.empty()) dir = ".";
    const std::string tmp =
        (dir / ("." + target.filename().string() + ".tmp." + std::to_string(::getpid()))).string();
    auto failure = [&](const std::string& what, int err) {
        ::unlink(tmp.c_str());
        return std::runtime_error("cannot write checkpoint '" + path + "': " + what + ": " +
                                  std::strerror(err) + " (the previous checkpoint is intact)");
    };
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) throw failure("creating " + tmp, errno);
    const std::vector<char>& data = w.data();
    size_t done = 0;
    while (done < data.size()) {
        size_t n = data.size() - done;
        if (failAfterBytesForTest >= 0) {
            if (done >= size_t(failAfterBytesForTest)) {
                ::close(fd);
                throw failure("writing", ENOSPC);
            }
            n = std::min(n, size_t(failAfterBytesForTest) - done);
        }
        const ssize_t k = ::write(fd, data.data() + done, n);
        if (k < 0) {
            if (errno == EINTR) continue;
            const int e = errno;
            ::close(fd);
            throw failure("writing", e);
        }
        done += size_t(k);
    }
    if (::fsync(fd) != 0) {
        const int e = errno;
        ::close(fd);
        throw failure("fsync", e);
    }
    if (::close(fd) != 0) throw failure("closing", errno);
    if (::rename(tmp.c_str(), path.c_str()) != 0) throw failure("renaming " + tmp, errno);
    const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd >= 0) {
        ::fsync(dfd);
        ::close(dfd);
    }
}

ProgressiveState readCheckpoint(const std::string& path, const CheckpointHeader& expected) {
    std::ifstream f(path, std::ios::binary);
    if (!f) throw InputError(path, "checkpoint: cannot open the file");
    std::vector<char> data((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    Reader r(data, path);
    char magic[8];
    r.bytes(magic, 8);
    if (std::memcmp(magic, kMagic, 8) != 0) r.fail("not a unibeam checkpoint (bad magic)");
    if (data.size() < 8 + 4 + 8) r.fail("the file is truncated");
    uint64_t stored;
    std::memcpy(&stored, data.data() + data.size() - 8, 8);
    const uint32_t format = r.pod<uint32_t>();
    if (format != kCheckpointFormat)
        r.fail("format version " + std::to_string(format) + ", this unibeam reads version " +
               std::to_string(kCheckpointFormat));
    if (stored != fnv1a(data.data(), data.size() - 8))
        throw InputError(path, "checkpoint: checksum mismatch: the file is corrupt or truncated");
    const std::string version = r.str();
    if (version != expected.version)
        r.fail("written by unibeam " + version + ", this is unibeam " + expected.version);
    const std::string scene = r.str();
    if (scene != expected.sceneDigest)
        r.fail("made for another scene file (digest " + scene + ", the scene now has " +
               expected.sceneDigest + ")");
    const std::string options = r.str();
    if (options != expected.options) {
        const auto a = optionLines(options), b = optionLines(expected.options);
        std::string diff;
        for (const auto& [k, v] : a) {
            auto it = b.find(k);
            const std::string now = it == b.end() ? "(not set)" : it->second;
            if (now != v) diff += (diff.empty() ? "" : ", ") + k + " was " + v + ", now " + now;
        }
        for (const auto& [k, v] : b)
            if (!a.count(k)) diff += (diff.empty() ? "" : ", ") + k + " was (not set), now " + v;
        r.fail("made with other options: " + diff);
    }
    const uint32_t w = r.pod<uint32_t>(), h = r.pod<uint32_t>();
    if (w != expected.width || h != expected.height)
        r.fail("made at " + std::to_string(w) + "x" + std::to_string(h) + ", the render is " +
               std::to_string(expected.width) + "x" + std::to_string(expected.height));
    const size_t n = size_t(w) * h * 3;
    ProgressiveState s;
    s.iterations = r.pod<int32_t>();
    s.seconds = r.pod<double>();
    if (s.iterations < 0) r.fail("negative iteration count");
    const uint32_t layers = r.pod<uint32_t>();
    if (layers > 64) r.fail("implausible layer count " + std::to_string(layers));
    for (uint32_t i = 0; i < layers; ++i) {
        s.layerNames.push_back(r.str());
        s.layerRejected.push_back(r.pod<uint64_t>());
        s.layers.push_back(r.doubles(n));
    }
    s.filmRejected = r.pod<uint64_t>();
    s.film = r.doubles(n);
    s.hasVariance = r.pod<uint8_t>() != 0;
    if (s.hasVariance) {
        s.varianceMean = r.doubles(n);
        s.varianceM2 = r.doubles(n);
    }
    const uint32_t counts = r.pod<uint32_t>();
    if (counts > 64) r.fail("implausible rejection count entries " + std::to_string(counts));
    for (uint32_t i = 0; i < counts; ++i) {
        std::string name = r.str();
        s.rejected.emplace_back(std::move(name), r.pod<uint64_t>());
    }
    return s;
}

}  // namespace ub
