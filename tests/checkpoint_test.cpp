// Checkpoint and resume (render/checkpoint.h, --checkpoint / --resume):
//  * the file round-trips the state exactly; a corrupt byte, a truncated file, another
//    format, unibeam version, scene or options are errors naming the file and the
//    difference;
//  * a write that fails (simulated ENOSPC) throws, leaves the previous checkpoint intact
//    and no temporary file;
//  * end to end: a render killed with SIGKILL at 10+ different moments and resumed each
//    time ends with the same EXR pixels and layers, bit for bit, as an uninterrupted one.
#include "render/checkpoint.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "core/error.h"
#include "core/image.h"

using namespace ub;
namespace fs = std::filesystem;

namespace {

fs::path tempDir(const std::string& name) {
    fs::path d =
        fs::temp_directory_path() / ("unibeam_ckpt_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

CheckpointHeader header() {
    CheckpointHeader h;
    h.version = "1.2.3";
    h.sceneDigest = "0123456789abcdef";
    h.options = "algorithm=upbp\nseed=7\n";
    h.width = 3;
    h.height = 2;
    return h;
}

ProgressiveState state() {
    ProgressiveState s;
    s.iterations = 5;
    s.seconds = 1.25;
    for (int i = 0; i < 18; ++i) s.film.push_back(0.1 * i + 1e-17);
    s.filmRejected = 2;
    s.layerNames = {"bpt", "bb1d"};
    s.layers = {s.film, std::vector<double>(18, 3.0)};
    s.layerRejected = {0, 4};
    s.hasVariance = true;
    s.varianceMean = std::vector<double>(18, 0.5);
    s.varianceM2 = std::vector<double>(18, 0.25);
    s.rejected = {{"bpt", 1}, {"bb1d", 9}};
    return s;
}

std::string messageOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.diagnostics().at(0).format();
    } catch (const std::exception& e) {
        return e.what();
    }
    return "";
}

}  // namespace

TEST(Checkpoint, RoundTripsExactly) {
    const fs::path dir = tempDir("roundtrip");
    const std::string f = (dir / "a.ckpt").string();
    writeCheckpoint(f, header(), state());
    const ProgressiveState s = readCheckpoint(f, header());
    const ProgressiveState w = state();
    EXPECT_EQ(s.iterations, w.iterations);
    EXPECT_EQ(s.seconds, w.seconds);
    EXPECT_EQ(s.film, w.film);
    EXPECT_EQ(s.filmRejected, w.filmRejected);
    EXPECT_EQ(s.layerNames, w.layerNames);
    EXPECT_EQ(s.layers, w.layers);
    EXPECT_EQ(s.layerRejected, w.layerRejected);
    EXPECT_EQ(s.varianceM2, w.varianceM2);
    EXPECT_EQ(s.rejected, w.rejected);
    fs::remove_all(dir);
}

TEST(Checkpoint, MismatchesAndDamageAreErrorsNamingTheDifference) {
    const fs::path dir = tempDir("mismatch");
    const std::string f = (dir / "a.ckpt").string();
    writeCheckpoint(f, header(), state());
    CheckpointHeader h = header();
    h.options = "algorithm=vpt\nseed=7\n";
    std::string m = messageOf([&] { readCheckpoint(f, h); });
    EXPECT_NE(m.find("a.ckpt"), std::string::npos) << m;
    EXPECT_NE(m.find("algorithm was upbp, now vpt"), std::string::npos) << m;
    h = header();
    h.sceneDigest = "ffffffffffffffff";
    m = messageOf([&] { readCheckpoint(f, h); });
    EXPECT_NE(m.find("another scene"), std::string::npos) << m;
    h = header();
    h.version = "9.9";
    m = messageOf([&] { readCheckpoint(f, h); });
    EXPECT_NE(m.find("written by unibeam 1.2.3"), std::string::npos) << m;
    h = header();
    h.width = 4;
    m = messageOf([&] { readCheckpoint(f, h); });
    EXPECT_NE(m.find("made at 3x2"), std::string::npos) << m;
    // One flipped byte in the middle: checksum.
    std::string bytes;
    {
        std::ifstream in(f, std::ios::binary);
        std::stringstream ss;
        ss << in.rdbuf();
        bytes = ss.str();
    }
    std::string bad = bytes;
    bad[bad.size() / 2] ^= 0x10;
    std::ofstream((dir / "bad.ckpt").string(), std::ios::binary) << bad;
    m = messageOf([&] { readCheckpoint((dir / "bad.ckpt").string(), header()); });
    EXPECT_NE(m.find("checksum mismatch"), std::string::npos) << m;
    for (size_t cut : {size_t(3), size_t(40), bytes.size() / 2, bytes.size() - 1}) {
        std::ofstream((dir / "cut.ckpt").string(), std::ios::binary) << bytes.substr(0, cut);
        m = messageOf([&] { readCheckpoint((dir / "cut.ckpt").string(), header()); });
        EXPECT_TRUE(m.find("truncated") != std::string::npos ||
                    m.find("checksum mismatch") != std::string::npos)
            << cut << ": " << m;
    }
    std::ofstream((dir / "junk.ckpt").string()) << "hello, this is no checkpoint at all";
    m = messageOf([&] { readCheckpoint((dir / "junk.ckpt").string(), header()); });
    EXPECT_NE(m.find("not a unibeam checkpoint"), std::string::npos) << m;
    fs::remove_all(dir);
}

TEST(Checkpoint, FullDiskKeepsThePreviousCheckpoint) {
    const fs::path dir = tempDir("enospc");
    const std::string f = (dir / "a.ckpt").string();
    writeCheckpoint(f, header(), state());
    ProgressiveState next = state();
    next.iterations = 6;
    for (long long failAfter : {0LL, 100LL, 500LL}) {
        const std::string m = messageOf([&] { writeCheckpoint(f, header(), next, failAfter); });
        EXPECT_NE(m.find("No space left on device"), std::string::npos) << m;
        EXPECT_NE(m.find("previous checkpoint is intact"), std::string::npos) << m;
        EXPECT_EQ(readCheckpoint(f, header()).iterations, 5);
        int files = 0;
        for (const auto& e : fs::directory_iterator(dir)) files += e.is_regular_file();
        EXPECT_EQ(files, 1) << "a temporary file was left behind";
    }
    fs::remove_all(dir);
}

// kill -9 at 10 or more different moments of a checkpointed render, resuming each time.
TEST(Checkpoint, KilledRendersResumeToTheSameImageBitForBit) {
    const fs::path dir = tempDir("kill");
    const std::string bin = UNIBEAM_BINARY;
    const std::string scene = std::string(UNIBEAM_SOURCE_DIR) + "/scenes/cornell-fog.json";
    const std::string common = "'" + bin + "' render '" + scene +
                               "' -a upbp --backend host --resolution 40x40 -i 48 --seed 5 ";
    const std::string log = " >>'" + (dir / "log.txt").string() + "' 2>&1";
    ASSERT_EQ(std::system((common + "-o '" + (dir / "full.exr").string() + "'" + log).c_str()), 0);
    const std::string ck = (dir / "render.ckpt").string();
    const std::string out = (dir / "resumed.exr").string();
    std::mt19937 rng(1234);
    std::uniform_real_distribution<double> when(0.15, 0.9);
    int kills = 0, attempts = 0;
    while (kills < 10 && attempts < 60) {
        ++attempts;
        const bool resume = fs::exists(ck);
        char t[32];
        std::snprintf(t, sizeof(t), "%.3f", when(rng));
        const std::string cmd = "timeout -s KILL " + std::string(t) + " " + common +
                                (resume ? "--resume '" + ck + "'" : "--checkpoint '" + ck + "'") +
                                " --checkpoint-every 0.05 -o '" + out + "'" + log;
        const int status = std::system(cmd.c_str());
        const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        if (code == 137) {
            ++kills;
            continue;
        }
        ASSERT_EQ(code, 0) << cmd;
        fs::remove(ck);  // finished before the kill: start again, so every kill interrupts
        fs::remove(out);
    }
    EXPECT_GE(kills, 10) << attempts << " attempts";
    // Finish.
    const std::string finish = common + (fs::exists(ck) ? "--resume '" + ck + "'" : std::string()) +
                               " -o '" + out + "'" + log;
    ASSERT_EQ(std::system(finish.c_str()), 0);
    const Image a = readExr((dir / "full.exr").string()), b = readExr(out);
    ASSERT_EQ(a.pixels.size(), b.pixels.size());
    size_t differ = 0;
    for (size_t i = 0; i < a.pixels.size(); ++i)
        for (int c = 0; c < 3; ++c) differ += a.pixels[i][c] != b.pixels[i][c];
    EXPECT_EQ(differ, 0u) << "pixels differ after " << kills << " kills";
    std::printf("[ ckpt     ] %d kills in %d attempts, final image identical: %s\n", kills,
                attempts, differ == 0 ? "yes" : "no");
    // Resuming with other options is an error naming the option, exit 2.
    const std::string ck2 = (dir / "two.ckpt").string();
    ASSERT_EQ(std::system((common + "--checkpoint '" + ck2 + "' -o '" + out + "'" + log).c_str()),
              0);
    const std::string other =
        "'" + bin + "' render '" + scene +
        "' -a upbp --backend host --resolution 40x40 -i 50 --seed 6 --resume '" + ck2 + "' -o '" +
        out + "' >'" + (dir / "err.txt").string() + "' 2>&1";
    const int st = std::system(other.c_str());
    EXPECT_EQ(WIFEXITED(st) ? WEXITSTATUS(st) : -1, 2);
    std::ifstream e(dir / "err.txt");
    std::stringstream es;
    es << e.rdbuf();
    EXPECT_NE(es.str().find("seed was 5, now 6"), std::string::npos) << es.str();
    EXPECT_NE(es.str().find("two.ckpt"), std::string::npos) << es.str();
    fs::remove_all(dir);
}
