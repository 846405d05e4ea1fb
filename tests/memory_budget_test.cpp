// --max-memory (core/memory_budget.h): sizes parse, reservations are checked before the
// memory is taken and released, a render over the budget stops with a message naming what
// grew and the option, exit 2; an iteration after the first that runs over it keeps the
// finished iterations (renderProgressive), and a generous budget changes nothing.
#include "core/memory_budget.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/parallel_gather.h"
#include "render/progressive.h"

using namespace ub;
namespace fs = std::filesystem;

TEST(MemoryBudget, ParsesSizes) {
    EXPECT_EQ(parseMemorySize("1024"), 1024u);
    EXPECT_EQ(parseMemorySize("512M"), 512u << 20);
    EXPECT_EQ(parseMemorySize("8G"), size_t(8) << 30);
    EXPECT_EQ(parseMemorySize("1.5KiB"), 1536u);
    EXPECT_EQ(parseMemorySize("2mb"), 2u << 20);
    for (const char* bad : {"", "M", "12X", "-5", "0", "1e400G", "1.2.3G"})
        EXPECT_THROW(parseMemorySize(bad), std::invalid_argument) << bad;
    EXPECT_GT(defaultMemoryBudget(), size_t(64) << 20);
}

TEST(MemoryBudget, ReservesBeforeGrowingAndReleases) {
    MemoryBudget b(1000);
    std::vector<double> v;
    for (int i = 0; i < 64; ++i) pushBudgeted(v, 1.0, &b, "values", "fewer");
    EXPECT_EQ(b.used(), v.capacity() * sizeof(double));
    try {
        reserveFor(v, 1000, &b, "values", "use fewer values");
        ADD_FAILURE() << "no error";
    } catch (const MemoryBudgetError& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("the values need"), std::string::npos) << m;
        EXPECT_NE(m.find("use fewer values"), std::string::npos) << m;
        EXPECT_NE(m.find("--max-memory"), std::string::npos) << m;
    }
    EXPECT_LT(v.capacity(), 1000u);  // nothing was allocated
    {
        MemoryReservation r(&b, b.limit() - b.used(), "lookup", "less");
        EXPECT_EQ(b.used(), b.limit());
    }
    EXPECT_EQ(b.used(), v.capacity() * sizeof(double));
    MemoryBudget unlimited(0);
    reserveFor(v, 100000, &unlimited, "values", "fewer");
    EXPECT_GE(v.capacity(), 100000u);
}

namespace {

/// An integrator whose iteration 3 runs over the budget.
class OverBudgetAtThree : public Integrator {
  public:
    void renderIteration(int iteration, Image& out) override {
        if (iteration == 3) throw MemoryBudgetError("memory budget exceeded: test");
        out = Image(2, 2);
        for (Rgb& p : out.pixels) p = Rgb(float(iteration));
    }
    RejectionCounts rejectedContributions() const override { return {}; }
};

}  // namespace

TEST(MemoryBudget, LaterIterationOverBudgetKeepsFinishedWork) {
    OverBudgetAtThree integrator;
    ProgressiveOptions o;
    o.iterations = 10;
    const ProgressiveResult r = renderProgressive(integrator, 2, 2, o);
    EXPECT_EQ(r.iterations, 3);
    EXPECT_NE(r.stopError.find("memory budget exceeded"), std::string::npos);
    EXPECT_FLOAT_EQ(r.image.pixels[0].x, 1.0f);  // (0 + 1 + 2) / 3
}

TEST(MemoryBudget, CliRejectsARenderOverTheBudget) {
    const fs::path dir = fs::temp_directory_path() / ("unibeam_mem_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const std::string scene = std::string(UNIBEAM_SOURCE_DIR) + "/scenes/cornell-fog.json";
    auto run = [&](const std::string& extra) {
        const std::string cmd = "'" + std::string(UNIBEAM_BINARY) + "' render '" + scene +
                                "' -a upbp --backend host --resolution 48x48 -i 2 -o '" +
                                (dir / "x.exr").string() + "' " + extra + " >'" +
                                (dir / "log.txt").string() + "' 2>&1";
        const int st = std::system(cmd.c_str());
        std::ifstream f(dir / "log.txt");
        std::stringstream ss;
        ss << f.rdbuf();
        return std::make_pair(WIFEXITED(st) ? WEXITSTATUS(st) : -1, ss.str());
    };
    auto [code, log] = run("--max-memory 1M");
    EXPECT_EQ(code, 2) << log;
    EXPECT_NE(log.find("memory budget exceeded"), std::string::npos) << log;
    EXPECT_NE(log.find("--max-memory"), std::string::npos) << log;
    std::tie(code, log) = run("--max-memory lots");
    EXPECT_EQ(code, 2) << log;
    EXPECT_NE(log.find("--max-memory: expected a size"), std::string::npos) << log;
    std::tie(code, log) = run("--max-memory 256M");
    EXPECT_EQ(code, 0) << log;
    fs::remove_all(dir);
}

// gatherParts (core/parallel_gather.h): the serial concatenation, element for element; a
// smaller gather keeps the capacity; growth is reserved in the budget, and growth beyond
// the budget throws before anything is copied.
TEST(ParallelGather, EqualsTheSerialConcatenationWithinTheBudget) {
    std::vector<std::vector<int>> parts(300);
    std::vector<int> serial;
    for (size_t c = 0; c < parts.size(); ++c)
        for (size_t k = 0; k < (c * 7) % 13; ++k) {  // some parts empty
            parts[c].push_back(int(c * 100 + k));
            serial.push_back(int(c * 100 + k));
        }
    MemoryBudget budget(size_t(1) << 20);
    std::vector<int> dst;
    auto part = [&](size_t c) -> auto& {
        return parts[c];
    };
    gatherParts(dst, parts.size(), part, &budget, "test records", "less");
    EXPECT_EQ(dst, serial);
    EXPECT_GE(budget.used(), serial.size() * sizeof(int));
    const size_t capacity = dst.capacity();
    gatherParts(dst, 100, part, &budget, "test records", "less");
    EXPECT_EQ(dst, std::vector<int>(serial.begin(), serial.begin() + std::ptrdiff_t(dst.size())));
    EXPECT_EQ(dst.capacity(), capacity);
    MemoryBudget small(64);
    std::vector<int> other;
    EXPECT_THROW(gatherParts(other, parts.size(), part, &small, "test records", "less"),
                 MemoryBudgetError);
}
