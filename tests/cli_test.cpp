// End-to-end tests of the `unibeam` program (UNIBEAM_BINARY): rendering a bundled scene,
// output files and their metadata, exit codes and messages for bad input, `info`,
// `--version`/`--help`, and SIGINT during a render.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/image.h"

extern char** environ;

namespace ub {
namespace {

namespace fs = std::filesystem;

const std::string kBinary = UNIBEAM_BINARY;
const std::string kScene = std::string(UNIBEAM_SOURCE_DIR) + "/scenes/cornell-large-light.json";

struct RunResult {
    int exitCode = -1;
    std::string out, err;
};

std::string readFile(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

/// Fresh temporary directory per test.
fs::path tempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    fs::path d = fs::temp_directory_path() /
                 ("unibeam_cli_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

std::string quote(const std::string& s) {
    std::string q = "'";
    for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

/// Runs the binary with args (each shell-quoted), capturing stdout and stderr.
RunResult runUnibeam(const std::vector<std::string>& args, const fs::path& dir,
                     bool inDir = false) {
    std::string cmd =
        (inDir ? "cd " + quote(dir.string()) + " && " : std::string()) + quote(kBinary);
    for (const auto& a : args) cmd += " " + quote(a);
    fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
    cmd += " >" + quote(out.string()) + " 2>" + quote(err.string()) + " </dev/null";
    int status = std::system(cmd.c_str());
    RunResult r;
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = readFile(out);
    r.err = readFile(err);
    return r;
}

/// Width and height from a PNG's IHDR chunk (bytes 16..23, big-endian), after checking
/// the signature.
bool pngSize(const fs::path& p, int* w, int* h) {
    std::string d = readFile(p);
    const std::string sig = "\x89PNG\r\n\x1a\n";
    if (d.size() < 24 || d.compare(0, 8, sig) != 0 || d.compare(12, 4, "IHDR") != 0) return false;
    auto be32 = [&](size_t o) {
        return int((uint32_t(uint8_t(d[o])) << 24) | (uint32_t(uint8_t(d[o + 1])) << 16) |
                   (uint32_t(uint8_t(d[o + 2])) << 8) | uint32_t(uint8_t(d[o + 3])));
    };
    *w = be32(16);
    *h = be32(20);
    return true;
}

TEST(Cli, RenderWritesExrAndPngWithMetadata) {
    ASSERT_TRUE(fs::exists(kScene)) << kScene;
    fs::path dir = tempDir();
    fs::path exr = dir / "out.exr", png = dir / "out.png";
    RunResult r = runUnibeam(
        {"render", kScene, "--resolution", "32x24", "-i", "2", "-o", exr.string(), "--png",
         png.string(), "--seed", "5", "--max-length", "4", "--threads", "2", "--exposure", "0.5"},
        dir);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    ImageMetadata meta;
    Image img = readExr(exr.string(), &meta);
    EXPECT_EQ(img.width, 32);
    EXPECT_EQ(img.height, 24);
    EXPECT_EQ(meta["technique"], "pt");
    EXPECT_EQ(meta["iterations"], "2");
    EXPECT_EQ(meta["seed"], "5");
    EXPECT_EQ(meta["resolution"], "32x24");
    EXPECT_EQ(meta["maxPathLength"], "4");
    EXPECT_EQ(meta["scene"], kScene);
    EXPECT_EQ(meta["interrupted"], "false");
    EXPECT_FALSE(meta["renderTimeSeconds"].empty());
    EXPECT_GT(luminance(img.mean()), 0.0f) << "the Cornell box should not render black";
    int w = 0, h = 0;
    ASSERT_TRUE(pngSize(png, &w, &h));
    EXPECT_EQ(w, 32);
    EXPECT_EQ(h, 24);
    // The contribution guard's counts (render/contribution_guard.h), zeros included.
    EXPECT_EQ(meta["unibeam.rejected.pt"], "0");
    EXPECT_EQ(meta["unibeam.rejected.film"], "0");
    EXPECT_NE(r.err.find("unibeam: rejected contributions (NaN, Inf or negative): pt 0, film 0\n"),
              std::string::npos)
        << r.err;
    // Non-terminal stderr: plain progress lines, no carriage returns.
    EXPECT_NE(r.err.find("unibeam: iteration 2/2"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find('\r'), std::string::npos);

    // Same seed, thread count 1: bit-identical image.
    fs::path exr1 = dir / "out1.exr";
    RunResult r1 = runUnibeam({"render", kScene, "--resolution", "32x24", "-i", "2", "-o",
                               exr1.string(), "--seed", "5", "--max-length", "4", "--threads", "1"},
                              dir);
    ASSERT_EQ(r1.exitCode, 0) << r1.err;
    Image img1 = readExr(exr1.string());
    ASSERT_EQ(img1.pixels.size(), img.pixels.size());
    for (size_t i = 0; i < img.pixels.size(); ++i)
        ASSERT_TRUE(img1.pixels[i].x == img.pixels[i].x && img1.pixels[i].y == img.pixels[i].y &&
                    img1.pixels[i].z == img.pixels[i].z)
            << "pixel " << i;
    fs::remove_all(dir);
}

// upbp: one rejection count per technique layer (and the film) on stderr and in the EXR.
TEST(Cli, UpbpReportsRejectionsPerTechnique) {
    const std::string scene = std::string(UNIBEAM_SOURCE_DIR) + "/scenes/cornell-fog.json";
    fs::path dir = tempDir();
    fs::path exr = dir / "upbp.exr";
    RunResult r = runUnibeam(
        {"render", scene, "-a", "upbp", "--resolution", "12x12", "-i", "1", "-o", exr.string()},
        dir);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    ImageMetadata meta;
    readExr(exr.string(), &meta);
    std::string expected = "unibeam: rejected contributions (NaN, Inf or negative): ";
    for (const char* t : {"bpt", "surf", "pp3d", "pb2d", "bp2d", "bb1d", "film"}) {
        EXPECT_EQ(meta[std::string("unibeam.rejected.") + t], "0") << t;
        expected += std::string(t) + " 0" + (std::string(t) == "film" ? "\n" : ", ");
    }
    EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
    fs::remove_all(dir);
}

// -t: the render stops after the iteration during which the limit passed; without -o the
// EXR goes to SCENE_STEM.exr in the current directory.
TEST(Cli, TimeLimitAndDefaultOutputName) {
    ASSERT_TRUE(fs::exists(kScene)) << kScene;
    fs::path dir = tempDir();
    auto start = std::chrono::steady_clock::now();
    RunResult r = runUnibeam({"render", kScene, "--resolution", "16x16", "-t", "0.3"}, dir, true);
    double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_EQ(r.exitCode, 0) << r.err;
    ImageMetadata meta;
    Image img = readExr((dir / "cornell-large-light.exr").string(), &meta);
    EXPECT_EQ(img.width, 16);
    EXPECT_GE(std::stoi(meta["iterations"]), 1);
    EXPECT_GE(std::stod(meta["renderTimeSeconds"]), 0.3);
    EXPECT_LT(wall, 60.0);
    fs::remove_all(dir);
}

// A Mitsuba scene whose integrator is ptracer renders with lt when -a is not given; -a
// chooses another algorithm.
TEST(Cli, PtracerSceneRendersWithLightTracingUnlessAIsGiven) {
    const std::string scene =
        std::string(UNIBEAM_SOURCE_DIR) + "/tests/data/mitsuba/interop_ptracer.xml";
    fs::path dir = tempDir();
    RunResult r = runUnibeam({"render", scene, "-i", "1", "-o", (dir / "a.exr").string()}, dir);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("the scene's integrator renders with lt"), std::string::npos) << r.err;
    ImageMetadata meta;
    readExr((dir / "a.exr").string(), &meta);
    EXPECT_EQ(meta["technique"], "lt");
    r = runUnibeam({"render", scene, "-a", "pt", "-i", "1", "-o", (dir / "b.exr").string()}, dir);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    readExr((dir / "b.exr").string(), &meta);
    EXPECT_EQ(meta["technique"], "pt");
    fs::remove_all(dir);
}

// Without -a a scene with media renders with vpt (Mitsuba's volpath scenes, and JSON scenes),
// a ptracer scene with media with vlt; -a pt on it stays an error naming the volumetric ones.
TEST(Cli, MediaSceneRendersWithVptUnlessAIsGiven) {
    const std::string scene = std::string(UNIBEAM_SOURCE_DIR) + "/tests/data/mitsuba/media.xml";
    fs::path dir = tempDir();
    RunResult r = runUnibeam(
        {"render", scene, "--resolution", "16x16", "-i", "1", "-o", (dir / "a.exr").string()}, dir);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("the scene has participating media: renders with vpt"), std::string::npos)
        << r.err;
    ImageMetadata meta;
    readExr((dir / "a.exr").string(), &meta);
    EXPECT_EQ(meta["technique"], "vpt");
    r = runUnibeam({"render", scene, "-a", "pt", "-i", "1", "-o", (dir / "b.exr").string()}, dir);
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find("use a volumetric algorithm"), std::string::npos) << r.err;
    // A ptracer integrator on the same scene: vlt.
    std::string xml = readFile(scene);
    const size_t at = xml.find("<integrator type=\"volpath\">");
    ASSERT_NE(at, std::string::npos);
    xml.replace(at, std::string("<integrator type=\"volpath\">").size(),
                "<integrator type=\"ptracer\">");
    // The copy lives in the test's folder: its relative file names made absolute.
    const std::string base = fs::path(scene).parent_path().string() + "/";
    for (const std::string key : {"filename=\"", "value=\"volumes/"})
        for (size_t p = xml.find(key); p != std::string::npos; p = xml.find(key, p + 1))
            xml.insert(p + key.size() - (key[0] == 'v' ? 8 : 0), base);
    const fs::path copy = dir / "media_ptracer.xml";
    std::ofstream(copy) << xml;
    r = runUnibeam({"render", copy.string(), "--resolution", "16x16", "-i", "1", "-o",
                    (dir / "c.exr").string()},
                   dir);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    readExr((dir / "c.exr").string(), &meta);
    EXPECT_EQ(meta["technique"], "vlt");
    fs::remove_all(dir);
}

TEST(Cli, BadFlagsExitTwoWithMessage) {
    ASSERT_TRUE(fs::exists(kScene)) << kScene;
    fs::path dir = tempDir();
    const std::string out = (dir / "o.exr").string();
    struct Case {
        std::vector<std::string> args;
        std::string message;
    };
    const std::vector<Case> cases = {
        {{"render", kScene, "--bogus"}, "--bogus"},
        {{"render", kScene, "-t", "1", "-i", "2", "-o", out}, "excludes"},
        {{"render", kScene, "-i", "0", "-o", out}, "--iterations"},
        {{"render", kScene, "-i", "-3", "-o", out}, "--iterations"},
        {{"render", kScene, "-i", "two", "-o", out}, "--iterations"},
        {{"render", kScene, "-t", "0", "-o", out}, "--time"},
        {{"render", kScene, "-t", "-1", "-o", out}, "--time"},
        {{"render", kScene, "--threads", "0", "-o", out}, "--threads"},
        {{"render", kScene, "--resolution", "32by32", "-o", out}, "--resolution"},
        {{"render", kScene, "--resolution", "0x32", "-o", out}, "--resolution"},
        {{"render", kScene, "--resolution", "32x", "-o", out}, "--resolution"},
        {{"render", kScene, "-a", "nope", "-o", out}, "unknown algorithm 'nope' (valid: pt"},
        {{"render", kScene, "-o", (dir / "no/such/dir/o.exr").string()}, "does not exist"},
        {{"render", kScene, "-o", (dir / "o.png").string()}, "must end in .exr"},
        {{"render", kScene, "-o", out, "--png", (dir / "p.jpg").string()}, "must end in .png"},
        {{"render", kScene, "-o", dir.string() + "/"}, "-o/--output"},
        {{"render", kScene, "--mis", "cubic", "-o", out}, "--mis"},
        {{"render", kScene, "--seed", "-1", "-o", out}, "--seed"},
        {{"render", kScene, "--max-length", "0", "-o", out}, "--max-length"},
        {{"render", kScene, "--radius", "-0.1", "-o", out}, "--radius"},
        {{"render", kScene, "--alpha", "1.5", "-o", out}, "--alpha"},
        // NaN or overflowing exposures made every PNG pixel garbage; a billion threads hung TBB.
        {{"render", kScene, "--exposure", "nan", "-o", out},
         "--exposure: expected a number in [-64, 64], got 'nan'"},
        {{"render", kScene, "--exposure", "1e999", "-o", out}, "--exposure"},
        {{"render", kScene, "--threads", "999999999", "-o", out},
         "--threads: expected an integer in [1, 4096], got '999999999'"},
        // UPBP technique sets and options.
        {{"render", kScene, "-a", "upbp:bpt+foo", "-o", out}, "unknown technique 'foo'"},
        {{"render", kScene, "-a", "upbp:", "-o", out}, "no technique after 'upbp:'"},
        {{"render", kScene, "-a", "upbp:pp3d+pp3d", "-o", out}, "'pp3d' is given twice"},
        {{"render", kScene, "-a", "upbp", "--radius-bb1d", "0", "-o", out}, "--radius-bb1d"},
        {{"render", kScene, "-a", "upbp", "--alpha-pp3d", "2", "-o", out}, "--alpha-pp3d"},
        {{"render", kScene, "-a", "upbp", "--photon-beams", "medium", "-o", out}, "--photon-beams"},
        {{"render", kScene, "-a", "upbp", "--query-beams", "x", "-o", out}, "--query-beams"},
        {{"render", kScene, "-a", "upbp", "--beam-paths", "0", "-o", out}, "--beam-paths"},
        {{"render", kScene, "-a", "upbp", "--backend", "gpu", "-o", out}, "--backend"},
        {{"render", kScene, "-a", "upbp", "--cl-device", "x", "-o", out},
         "--cl-device: expected PLATFORM:DEVICE"},
        {{"render", kScene, "-a", "upbp", "--backend", "opencl", "--cl-device", "9:9", "-o", out},
         "no device 9:9"},
        {{"render"}, "scene"},
        {{"frobnicate"}, "frobnicate"},
        {{}, "subcommand"},
    };
    for (const auto& c : cases) {
        std::string joined;
        for (const auto& a : c.args) joined += a + " ";
        RunResult r = runUnibeam(c.args, dir);
        EXPECT_EQ(r.exitCode, 2) << joined << "\n" << r.err;
        EXPECT_NE(r.err.find(c.message), std::string::npos)
            << joined << ": expected '" << c.message << "' in:\n"
            << r.err;
        EXPECT_FALSE(fs::exists(out)) << joined;
    }
    fs::remove_all(dir);
}

TEST(Cli, MissingOrBadSceneExitsTwo) {
    fs::path dir = tempDir();
    RunResult r = runUnibeam(
        {"render", (dir / "missing.json").string(), "-o", (dir / "o.exr").string()}, dir);
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.err.find("missing.json"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("does not exist"), std::string::npos) << r.err;

    RunResult ri = runUnibeam({"info", (dir / "missing.json").string()}, dir);
    EXPECT_EQ(ri.exitCode, 2);
    EXPECT_NE(ri.err.find("missing.json"), std::string::npos) << ri.err;

    // A malformed scene file: the loader's diagnostic is printed, exit 2.
    fs::path bad = dir / "bad.json";
    std::ofstream(bad) << "{ \"camera\": [1, 2,, }";
    RunResult rb = runUnibeam({"render", bad.string(), "-o", (dir / "o.exr").string()}, dir);
    EXPECT_EQ(rb.exitCode, 2) << rb.err;
    EXPECT_NE(rb.err.find("bad.json"), std::string::npos) << rb.err;
    EXPECT_FALSE(fs::exists(dir / "o.exr"));
    fs::remove_all(dir);
}

TEST(Cli, DevicesListsTheOpenClDevices) {
    fs::path dir = tempDir();
    RunResult r = runUnibeam({"devices"}, dir);
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.out.find("0:0"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("compute units"), std::string::npos) << r.out;
    fs::remove_all(dir);
}

TEST(Cli, InfoDescribesScene) {
    ASSERT_TRUE(fs::exists(kScene)) << kScene;
    fs::path dir = tempDir();
    RunResult r = runUnibeam({"info", kScene}, dir);
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_FALSE(r.out.empty());
    EXPECT_NE(r.out.find("ight"), std::string::npos) << "lights should be listed:\n" << r.out;
    fs::remove_all(dir);
}

TEST(Cli, VersionAndHelp) {
    fs::path dir = tempDir();
    RunResult v = runUnibeam({"--version"}, dir);
    EXPECT_EQ(v.exitCode, 0);
    EXPECT_NE(v.out.find(std::string("unibeam ") + UNIBEAM_VERSION), std::string::npos) << v.out;
    RunResult h = runUnibeam({"--help"}, dir);
    EXPECT_EQ(h.exitCode, 0);
    EXPECT_NE(h.out.find("render"), std::string::npos);
    EXPECT_NE(h.out.find("info"), std::string::npos);
    RunResult rh = runUnibeam({"render", "--help"}, dir);
    EXPECT_EQ(rh.exitCode, 0);
    for (const char* flag :
         {"--algorithm", "--time", "--iterations", "--output", "--png", "--exposure", "--threads",
          "--seed", "--max-length", "--resolution", "--mis", "--radius", "--alpha"})
        EXPECT_NE(rh.out.find(flag), std::string::npos) << flag;
    RunResult ih = runUnibeam({"info", "--help"}, dir);
    EXPECT_EQ(ih.exitCode, 0);
    EXPECT_NE(ih.out.find("scene"), std::string::npos);
    fs::remove_all(dir);
}

// SIGINT during a long (time-limited) render: the iteration in progress finishes, the
// image so far is written with its metadata, and the exit status is 0.
// unibeam compare IMAGE REF: metrics, threshold (exit 0/1), --diff PNG, bad input (exit 2).
TEST(Cli, CompareReportsErrorsThresholdAndDiff) {
    const fs::path dir = tempDir();
    const std::string a = (dir / "a.exr").string(), b = (dir / "b.exr").string();
    for (const auto& [file, seed] : {std::pair{a, "1"}, std::pair{b, "2"}}) {
        RunResult r = runUnibeam({"render", kScene, "-a", "pt", "--resolution", "32x24", "-i", "4",
                                  "--seed", seed, "-o", file},
                                 dir);
        ASSERT_EQ(r.exitCode, 0) << r.err;
    }
    RunResult same = runUnibeam({"compare", a, a, "--threshold", "0"}, dir);
    EXPECT_EQ(same.exitCode, 0) << same.out << same.err;
    EXPECT_NE(same.out.find("overall RMSE 0  relMSE 0  MAE 0"), std::string::npos) << same.out;
    RunResult diff = runUnibeam({"compare", a, b, "--diff", (dir / "d.png").string()}, dir);
    EXPECT_EQ(diff.exitCode, 0) << diff.err;
    for (const char* s : {"R       RMSE", "G       RMSE", "B       RMSE", "overall RMSE"})
        EXPECT_NE(diff.out.find(s), std::string::npos) << diff.out;
    int w = 0, h = 0;
    ASSERT_TRUE(pngSize(dir / "d.png", &w, &h));
    EXPECT_EQ(w, 32);
    EXPECT_GT(h, 24);
    RunResult fail = runUnibeam({"compare", a, b, "--threshold", "1e-9", "--metric", "mae"}, dir);
    EXPECT_EQ(fail.exitCode, 1) << fail.out << fail.err;
    EXPECT_NE(fail.out.find("mae"), std::string::npos);
    EXPECT_NE(fail.out.find("FAIL"), std::string::npos);
    // Bad input: exit 2 with the file named.
    RunResult missing = runUnibeam({"compare", a, (dir / "none.exr").string()}, dir);
    EXPECT_EQ(missing.exitCode, 2);
    EXPECT_NE(missing.err.find("none.exr"), std::string::npos) << missing.err;
    std::ofstream(dir / "junk.exr") << "not an exr";
    RunResult junk = runUnibeam({"compare", a, (dir / "junk.exr").string()}, dir);
    EXPECT_EQ(junk.exitCode, 2);
    EXPECT_NE(junk.err.find("junk.exr"), std::string::npos) << junk.err;
    RunResult small = runUnibeam({"render", kScene, "-a", "pt", "--resolution", "8x8", "-i", "1",
                                  "-o", (dir / "s.exr").string()},
                                 dir);
    ASSERT_EQ(small.exitCode, 0);
    RunResult size = runUnibeam({"compare", a, (dir / "s.exr").string()}, dir);
    EXPECT_EQ(size.exitCode, 2);
    EXPECT_NE(size.err.find("32x24"), std::string::npos) << size.err;
    RunResult noSpp = runUnibeam({"compare", a, b, "--ztest", b}, dir);
    EXPECT_EQ(noSpp.exitCode, 2);
    EXPECT_NE(noSpp.err.find("--spp"), std::string::npos) << noSpp.err;
    RunResult metric = runUnibeam({"compare", a, b, "--metric", "psnr"}, dir);
    EXPECT_EQ(metric.exitCode, 2);
}

TEST(Cli, SigintWritesImageAndExitsZero) {
    ASSERT_TRUE(fs::exists(kScene)) << kScene;
    fs::path dir = tempDir();
    fs::path exr = dir / "int.exr", errPath = dir / "stderr.txt";
    std::vector<std::string> args = {kBinary, "render", kScene, "--resolution", "32x32",
                                     "-t",    "120",    "-o",   exr.string()};
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 2, errPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
    posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
    pid_t pid = 0;
    ASSERT_EQ(posix_spawn(&pid, kBinary.c_str(), &actions, nullptr, argv.data(), environ), 0);
    posix_spawn_file_actions_destroy(&actions);

    // Wait for the first progress line (printed after the handlers are installed).
    using Clock = std::chrono::steady_clock;
    auto start = Clock::now();
    bool started = false;
    while (Clock::now() - start < std::chrono::seconds(60)) {
        if (readFile(errPath).find("unibeam: iteration") != std::string::npos) {
            started = true;
            break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    EXPECT_TRUE(started) << readFile(errPath);
    ::kill(pid, SIGINT);
    int status = 0;
    bool exited = false;
    start = Clock::now();
    while (Clock::now() - start < std::chrono::seconds(60)) {
        if (::waitpid(pid, &status, WNOHANG) == pid) {
            exited = true;
            break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    if (!exited) {
        ::kill(pid, SIGKILL);
        ::waitpid(pid, &status, 0);
        FAIL() << "unibeam did not exit within 60 s of SIGINT";
    }
    ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << WTERMSIG(status);
    EXPECT_EQ(WEXITSTATUS(status), 0) << readFile(errPath);
    ImageMetadata meta;
    Image img = readExr(exr.string(), &meta);
    EXPECT_EQ(img.width, 32);
    EXPECT_EQ(meta["interrupted"], "true");
    EXPECT_GE(std::stoi(meta["iterations"]), 1);
    EXPECT_NE(readFile(errPath).find("stopped by SIGINT"), std::string::npos);
    fs::remove_all(dir);
}

}  // namespace
}  // namespace ub
