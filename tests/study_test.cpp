// `unibeam study` end to end: a tiny study (two techniques, 24x24, a few iterations, its
// own upbp reference) writes convergence.csv with log-spaced checkpoints, summary.csv, the
// plot, the images and index.html; the report is loaded in headless Chromium (Debian's
// chromium, installed by scripts/setup.sh), whose rendered DOM must say that every image
// loaded. The screenshot is kept as a test artifact in the build tree
// (build/tests/artifacts/study_report.png). Bad study options exit 2.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

const std::string kBinary = UNIBEAM_BINARY;

std::string readFile(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

int runShell(const std::string& cmd) {
    const int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

fs::path tempDir(const std::string& name) {
    fs::path d =
        fs::temp_directory_path() / ("unibeam_study_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

std::string chromium() {
    for (const char* c : {"/usr/bin/chromium", "/usr/bin/chromium-browser"})
        if (fs::exists(c)) return c;
    return "";
}

}  // namespace

TEST(Study, WritesCsvPlotAndAReportThatRendersInChromium) {
    const fs::path dir = tempDir("report");
    const fs::path out = dir / "study";
    const std::string scene = std::string(UNIBEAM_SOURCE_DIR) + "/scenes/cornell-fog.json";
    const std::string cmd = "'" + kBinary + "' study '" + scene +
                            "' --techniques upbp,upbp:bpt+bb1d,vpt --iterations 12 "
                            "--resolution 24x24 --backend host --out '" +
                            out.string() + "' >'" + (dir / "log.txt").string() + "' 2>&1";
    ASSERT_EQ(runShell(cmd), 0) << readFile(dir / "log.txt");
    const std::string log = readFile(dir / "log.txt");
    EXPECT_NE(log.find("no --reference given: rendering one with upbp"), std::string::npos) << log;
    // convergence.csv: checkpoints 1, 2, 3, 4, 6, 8, 11, 12 per technique.
    std::istringstream csv(readFile(out / "convergence.csv"));
    std::string line;
    std::getline(csv, line);
    EXPECT_EQ(line, "technique,iteration,seconds,rmse,relmse,mae");
    std::map<std::string, std::vector<int>> its;
    while (std::getline(csv, line)) {
        std::stringstream ls(line);
        std::string t, it;
        std::getline(ls, t, ',');
        std::getline(ls, it, ',');
        its[t].push_back(std::stoi(it));
    }
    const std::vector<int> expected = {1, 2, 3, 4, 6, 8, 11, 12};
    for (const char* t : {"upbp", "upbp:bpt+bb1d", "vpt"}) EXPECT_EQ(its[t], expected) << t;
    const std::string summary = readFile(out / "summary.csv");
    EXPECT_NE(summary.find("\nvpt,12,"), std::string::npos) << summary;
    for (const char* f :
         {"convergence.png", "reference.exr", "reference.png", "upbp.exr", "upbp.png",
          "upbp.error.png", "upbp.bb1d.png", "upbp_bpt_bb1d.png", "vpt.png", "vpt.error.png"})
        EXPECT_TRUE(fs::is_regular_file(out / f)) << f << "\n" << log;

    // The report in headless Chromium: every <img> loaded.
    const std::string html = readFile(out / "index.html");
    int images = 0;
    for (size_t at = html.find("<img "); at != std::string::npos; at = html.find("<img ", at + 1))
        ++images;
    EXPECT_GE(images, 14);
    const std::string browser = chromium();
    ASSERT_FALSE(browser.empty())
        << "Chromium is needed to check the report (scripts/setup.sh installs Debian's "
           "chromium)";
    const std::string flags =
        " --headless --no-sandbox --disable-gpu --hide-scrollbars "
        "--virtual-time-budget=10000 ";
    const std::string url = "file://" + fs::absolute(out / "index.html").string();
    ASSERT_EQ(runShell("'" + browser + "'" + flags + "--dump-dom '" + url + "' >'" +
                       (dir / "dom.html").string() + "' 2>/dev/null"),
              0);
    const std::string dom = readFile(dir / "dom.html");
    const std::string want =
        "data-images=\"loaded " + std::to_string(images) + " of " + std::to_string(images) + "\"";
    EXPECT_NE(dom.find(want), std::string::npos) << "wanted " << want << " in Chromium's DOM:\n"
                                                 << dom.substr(0, 400);
    const fs::path artifacts = fs::path(UNIBEAM_BINARY).parent_path() / "tests" / "artifacts";
    fs::create_directories(artifacts);
    const fs::path shot = artifacts / "study_report.png";
    fs::remove(shot);
    EXPECT_EQ(runShell("'" + browser + "'" + flags + "--window-size=1400,2400 --screenshot='" +
                       shot.string() + "' '" + url + "' >/dev/null 2>&1"),
              0);
    EXPECT_GT(fs::exists(shot) ? fs::file_size(shot) : 0, 10000u) << shot;
    fs::remove_all(dir);
}

// Every study scene of scenes/README.md gives the CSV, the plot and the report (tiny
// budget: this checks that the study runs there, not what it finds).
TEST(Study, RunsOnEveryStudyScene) {
    const fs::path dir = tempDir("scenes");
    for (const char* s : {"study-thin-fog.json", "study-dense-medium.json", "cornell-fog.json",
                          "glass-medium-caustics.json", "cornell-smoke.json"}) {
        const fs::path out = dir / s;
        const std::string cmd = "'" + kBinary + "' study '" + std::string(UNIBEAM_SOURCE_DIR) +
                                "/scenes/" + s +
                                "' --techniques upbp:bpt+pp3d,upbp:bpt+bb1d --iterations 3 "
                                "--resolution 16x16 --backend host --out '" +
                                out.string() + "' >'" + (dir / "log.txt").string() + "' 2>&1";
        ASSERT_EQ(runShell(cmd), 0) << s << ": " << readFile(dir / "log.txt");
        for (const char* f : {"convergence.csv", "summary.csv", "convergence.png", "index.html",
                              "upbp_bpt_pp3d.png", "upbp_bpt_bb1d.error.png"})
            EXPECT_TRUE(fs::is_regular_file(out / f)) << s << ": " << f;
    }
    fs::remove_all(dir);
}

TEST(Study, BadOptionsExitTwo) {
    const fs::path dir = tempDir("bad");
    const std::string scene = std::string(UNIBEAM_SOURCE_DIR) + "/scenes/cornell-fog.json";
    auto run = [&](const std::string& args) {
        return runShell("'" + kBinary + "' study " + args + " >'" + (dir / "log.txt").string() +
                        "' 2>&1");
    };
    const std::string o = " --out '" + (dir / "o").string() + "'";
    EXPECT_EQ(run("'" + scene + "' --techniques nope --iterations 2" + o), 2);
    EXPECT_NE(readFile(dir / "log.txt").find("unknown technique 'nope'"), std::string::npos);
    EXPECT_EQ(run("'" + scene + "' --techniques vpt" + o), 2);  // no budget
    EXPECT_NE(readFile(dir / "log.txt").find("--time"), std::string::npos);
    EXPECT_EQ(run("'" + scene + "' --techniques vpt --time 1 --iterations 2" + o), 2);
    EXPECT_EQ(run("missing.json --techniques vpt --iterations 2" + o), 2);
    EXPECT_NE(readFile(dir / "log.txt").find("missing.json"), std::string::npos);
    EXPECT_EQ(run("'" + scene + "' --techniques vpt --iterations 2 --reference none.exr" + o), 2);
    EXPECT_NE(readFile(dir / "log.txt").find("none.exr"), std::string::npos);
    // An --out name the system refuses (a component over NAME_MAX): the folder check answers,
    // it does not throw std::filesystem's "File name too long".
    EXPECT_EQ(run("'" + scene + "' --techniques vpt --iterations 2 --out '" +
                  (dir / std::string(300, 'x') / "o").string() + "'"),
              2);
    EXPECT_NE(readFile(dir / "log.txt").find("--out: cannot write to folder"), std::string::npos);
    fs::remove_all(dir);
}
