// `unibeam study`: equal-time (or equal-iteration) comparison of techniques on one
// scene against a reference, with a convergence CSV, a log-log plot and a static
// HTML report (docs/studies.md).
//
// For each technique (any -a value) the progressive loop runs for the budget; at
// log-spaced iterations (ratio ~sqrt 2: 1, 2, 3, 4, 6, 8, 11, 16, ...) and at the last
// one the running average is compared with the reference (core/image_metrics.h) and a
// row goes to DIR/convergence.csv. The slope of log RMSE against log seconds, fitted by
// least squares over the checkpoints from the 4th iteration on, goes to
// DIR/summary.csv and the report: unbiased estimators sit near -0.5; progressive
// merging with radius exponent alpha converges at -alpha/2 ... -0.5 once its bias
// shrinks with the noise (Knaus and Zwicker 2011), and a flattening curve means a
// bias (or a reference error) larger than the noise.
#include <sys/utsname.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "app/commands.h"
#include "app/scene_access.h"
#include "core/error.h"
#include "core/file_status.h"
#include "core/image.h"
#include "core/image_metrics.h"
#include "render/film.h"
#include "render/integrator.h"
#include "render/progressive.h"
#include "render/upbp_techniques.h"
#include "scene/scene.h"

namespace ub {
extern const char* const kStudyPlotScript;  // tools/study_plot.py, embedded by CMake
}

namespace ub::app {
namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

struct Checkpoint {
    int iteration;
    double seconds;
    ImageError error;
};

struct TechniqueRun {
    std::string technique, slug;
    Image image;
    std::vector<std::pair<std::string, Image>> layers;
    std::vector<Checkpoint> checkpoints;
    int iterations = 0;
    double seconds = 0;
    double slope = NAN;
    std::string note;  ///< the integrator's setup note (e.g. the OpenCL device)
};

/// File-name form of a technique: letters, digits, '-' kept, others '_'.
std::string slugOf(const std::string& t) {
    std::string s;
    for (char c : t) s += std::isalnum(static_cast<unsigned char>(c)) || c == '-' ? c : '_';
    return s;
}

std::string htmlEscape(const std::string& s) {
    std::string o;
    for (char c : s) {
        if (c == '<')
            o += "&lt;";
        else if (c == '>')
            o += "&gt;";
        else if (c == '&')
            o += "&amp;";
        else if (c == '"')
            o += "&quot;";
        else
            o += c;
    }
    return o;
}

std::string cpuName() {
    std::ifstream f("/proc/cpuinfo");
    std::string line;
    while (std::getline(f, line))
        if (line.rfind("model name", 0) == 0) {
            size_t c = line.find(':');
            if (c != std::string::npos) return line.substr(c + 2);
        }
    return "unknown CPU";
}

/// Least-squares slope of log(rmse) against log(seconds) over checkpoints with iteration
/// >= 4 (NaN with fewer than 2 such points or a zero error).
double fitSlope(const std::vector<Checkpoint>& cps) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int n = 0;
    for (const Checkpoint& c : cps) {
        if (c.iteration < 4 || !(c.seconds > 0) || !(c.error.rmseAll > 0) ||
            !std::isfinite(c.error.rmseAll))
            continue;
        const double x = std::log(c.seconds), y = std::log(c.error.rmseAll);
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
        ++n;
    }
    if (n < 2) return NAN;
    const double den = n * sxx - sx * sx;
    return den > 0 ? (n * sxy - sx * sy) / den : NAN;
}

/// Runs one technique for the budget; checkpoints against ref when ref is non-null.
TechniqueRun runTechnique(const Scene& scene, const RenderOptions& options, double seconds,
                          int iterations, const Image* ref, const std::string& what) {
    TechniqueRun run;
    run.technique = options.algorithm;
    run.slug = slugOf(options.algorithm);
    std::unique_ptr<Integrator> integrator = makeIntegrator(scene, options);
    run.note = integrator->setupNote();
    if (!run.note.empty()) std::fprintf(stderr, "study: %s\n", run.note.c_str());
    const int w = scene.camera.width(), h = scene.camera.height();
    Film film(w, h);
    std::vector<Film> layerFilms;
    const std::vector<std::string> names = integrator->layerNames();
    for (size_t i = 0; i < names.size(); ++i) layerFilms.emplace_back(w, h);
    Image img;
    const Clock::time_point start = Clock::now();
    int next = 1;
    double lastReport = -1;
    for (int it = 0;; ++it) {
        const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
        const bool more = iterations > 0 ? it < iterations : (it == 0 || elapsed < seconds);
        if (!more || (it > 0 && stopRequested().load())) break;
        integrator->renderIteration(it, img);
        film.addIteration(img);
        if (const std::vector<Image>* layers = integrator->iterationLayers())
            for (size_t i = 0; i < layers->size() && i < layerFilms.size(); ++i)
                layerFilms[i].addIteration((*layers)[i]);
        run.iterations = it + 1;
        run.seconds = std::chrono::duration<double>(Clock::now() - start).count();
        const bool last = iterations > 0 ? run.iterations == iterations : run.seconds >= seconds;
        if (ref && (run.iterations == next || last)) {
            run.checkpoints.push_back(
                {run.iterations, run.seconds, imageError(film.average(), *ref)});
            while (next <= run.iterations)
                next = std::max(next + 1, int(std::lround(next * 1.41421356)));
        }
        if (run.seconds - lastReport >= 1.0 || last) {
            lastReport = run.seconds;
            std::fprintf(stderr, "study: %s: iteration %d, %.1f s%s\n", what.c_str(),
                         run.iterations, run.seconds,
                         iterations > 0
                             ? (" of " + std::to_string(iterations) + " iterations").c_str()
                             : (" of " + std::to_string(int(seconds)) + " s").c_str());
        }
    }
    if (ref && (run.checkpoints.empty() || run.checkpoints.back().iteration != run.iterations))
        run.checkpoints.push_back({run.iterations, run.seconds, imageError(film.average(), *ref)});
    run.image = film.average();
    for (size_t i = 0; i < names.size(); ++i)
        run.layers.emplace_back(names[i], layerFilms[i].average());
    run.slope = fitSlope(run.checkpoints);
    return run;
}

void writeImages(const fs::path& dir, const TechniqueRun& run, const Image& ref) {
    ImageMetadata meta;
    meta["software"] = std::string("unibeam ") + UNIBEAM_VERSION;
    meta["technique"] = run.technique;
    meta["iterations"] = std::to_string(run.iterations);
    writeExr((dir / (run.slug + ".exr")).string(), run.image, meta, run.layers);
    writePng((dir / (run.slug + ".png")).string(), run.image);
    writePng((dir / (run.slug + ".error.png")).string(), falseColourError(run.image, ref));
    for (const auto& l : run.layers)
        writePng((dir / (run.slug + "." + l.first + ".png")).string(), l.second);
}

std::string fmt(const char* f, double v) {
    char b[64];
    std::snprintf(b, sizeof(b), f, v);
    return b;
}

/// The static report (no server, no external files): images, synchronised crops, error
/// maps, layers, plot, table. Every <img> is counted when it loads; the body's
/// data-images attribute then reads "loaded N of N" (the test checks it).
void writeReport(const fs::path& dir, const StudyArgs& args, const Scene& scene,
                 const RenderOptions& base, const std::vector<TechniqueRun>& runs,
                 const std::string& referenceNote, bool havePlot, const std::string& plotNote) {
    std::ofstream h(dir / "index.html");
    utsname u{};
    uname(&u);
    h << "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>unibeam study: "
      << htmlEscape(fs::path(args.scene).filename().string()) << "</title>\n<style>\n"
      << "body{font-family:sans-serif;background:#1e1e1e;color:#ddd;margin:1em}"
         "table{border-collapse:collapse}td,th{border:1px solid #555;padding:2px 8px;"
         "text-align:right}th{background:#333}.row{display:flex;flex-wrap:wrap;gap:12px}"
         ".cell{text-align:center}.cell img{image-rendering:pixelated;display:block}"
         "canvas{image-rendering:pixelated;border:1px solid #777;display:block;margin-top:4px}"
         "code{color:#9cf}\n</style></head>\n<body data-images=\"loading\">\n";
    h << "<h1>Study of " << htmlEscape(args.scene) << "</h1>\n<ul>\n";
    h << "<li>resolution " << scene.camera.width() << "&times;" << scene.camera.height()
      << ", max path length " << base.maxPathLength << ", seed " << base.seed << ", budget "
      << (args.iterations > 0 ? std::to_string(args.iterations) + " iterations"
                              : fmt("%g s", args.timeSeconds))
      << " per technique</li>\n";
    h << "<li>reference: " << htmlEscape(referenceNote) << "</li>\n";
    h << "<li>machine: " << htmlEscape(cpuName()) << ", " << std::thread::hardware_concurrency()
      << " hardware threads, " << htmlEscape(u.sysname) << " " << htmlEscape(u.release)
      << "</li>\n<li>backend: " << htmlEscape(base.backend) << "</li>\n";
    for (const TechniqueRun& r : runs)
        if (!r.note.empty())
            h << "<li>" << htmlEscape(r.technique) << ": " << htmlEscape(r.note) << "</li>\n";
    h << "</ul>\n<h2>Final errors</h2>\n<table><tr><th>technique</th><th>iterations</th>"
         "<th>s/iteration</th><th>seconds</th><th>RMSE</th><th>relMSE</th><th>MAE</th>"
         "<th>slope</th></tr>\n";
    for (const TechniqueRun& r : runs) {
        const ImageError& e = r.checkpoints.back().error;
        h << "<tr><td style=\"text-align:left\"><code>" << htmlEscape(r.technique)
          << "</code></td><td>" << r.iterations << "</td><td>"
          << fmt("%.4g", r.seconds / std::max(1, r.iterations)) << "</td><td>"
          << fmt("%.3g", r.seconds) << "</td><td>" << fmt("%.4g", e.rmseAll) << "</td><td>"
          << fmt("%.4g", e.relMseAll) << "</td><td>" << fmt("%.4g", e.maeAll) << "</td><td>"
          << (std::isfinite(r.slope) ? fmt("%.2f", r.slope) : std::string("-")) << "</td></tr>\n";
    }
    h << "</table>\n<h2>Convergence</h2>\n";
    if (havePlot)
        h << "<img src=\"convergence.png\" alt=\"RMSE against time\" style=\"max-width:900px\">\n";
    else
        h << "<p>No plot: " << htmlEscape(plotNote) << " The data is in convergence.csv.</p>\n";
    h << "<h2>Images at equal " << (args.iterations > 0 ? "iterations" : "time")
      << "</h2>\n<p>Move the mouse over any image: the crops below all show the same "
         "region, 4&times; enlarged.</p>\n<div class=\"row\">\n";
    auto cell = [&](const std::string& src, const std::string& caption) {
        h << "<div class=\"cell\"><img class=\"study\" src=\"" << src << "\" alt=\""
          << htmlEscape(caption) << "\"><canvas class=\"crop\" width=\"128\" "
          << "height=\"128\"></canvas><div>" << htmlEscape(caption) << "</div></div>\n";
    };
    cell("reference.png", "reference");
    for (const TechniqueRun& r : runs) cell(r.slug + ".png", r.technique);
    h << "</div>\n<h2>Relative error |a &minus; r| / (r + 0.01)</h2>\n<div class=\"row\">\n";
    for (const TechniqueRun& r : runs) cell(r.slug + ".error.png", r.technique);
    h << "</div>\n";
    for (const TechniqueRun& r : runs) {
        if (r.layers.empty()) continue;
        h << "<h2>What each estimator contributes: <code>" << htmlEscape(r.technique)
          << "</code></h2>\n<div class=\"row\">\n";
        const double total = average(r.image.mean());
        for (const auto& l : r.layers) {
            const double share = total > 0 ? 100.0 * average(l.second.mean()) / total : 0.0;
            cell(r.slug + "." + l.first + ".png", l.first + fmt(" (%.1f%%)", share));
        }
        h << "</div>\n";
    }
    h << "<script>\n"
         "const imgs=[...document.querySelectorAll('img')];let done=0,bad=0;\n"
         "function count(ok){done++;if(!ok)bad++;if(done===imgs.length){document.body.dataset."
         "images=(bad?'failed ':'loaded ')+(done-bad)+' of '+imgs.length;draw(cx,cy);}}\n"
         "imgs.forEach(i=>{const big=()=>{if(i.classList.contains('study')&&i.naturalWidth>0&&"
         "i.naturalWidth<256)i.style.width=(i.naturalWidth*Math.ceil(256/i.naturalWidth))+'px';};"
         "i.addEventListener('load',big);big();});\n"
         "imgs.forEach(i=>{if(i.complete&&i.naturalWidth>0)count(true);else{i.onload=()=>count("
         "true);i.onerror=()=>count(false);}});\n"
         "let cx=0.5,cy=0.5;const Z=4;\n"
         "function draw(fx,fy){document.querySelectorAll('.cell').forEach(c=>{const i=c."
         "querySelector('img.study'),k=c.querySelector('canvas');if(!i||!k||!i.naturalWidth)"
         "return;const g=k.getContext('2d');g.imageSmoothingEnabled=false;const s=k.width/Z;"
         "const x=Math.max(0,Math.min(i.naturalWidth-s,fx*i.naturalWidth-s/2)),y=Math.max(0,"
         "Math.min(i.naturalHeight-s,fy*i.naturalHeight-s/2));g.clearRect(0,0,k.width,k."
         "height);g.drawImage(i,x,y,s,s,0,0,k.width,k.height);});}\n"
         "document.querySelectorAll('img.study').forEach(i=>i.addEventListener('mousemove',e=>{"
         "const r=i.getBoundingClientRect();cx=(e.clientX-r.left)/r.width;cy=(e.clientY-r.top)"
         "/r.height;draw(cx,cy);}));\n"
         "</script>\n</body></html>\n";
}

}  // namespace

int runStudy(const StudyArgs& args) {
    if (args.techniques.empty()) throw UsageError("--techniques: give at least one technique");
    const auto names = integratorNames();
    for (const std::string& t : args.techniques) {
        if (isUpbpAlgorithm(t)) {
            try {
                parseUpbpTechniques(t);
            } catch (const InputError& e) {
                throw UsageError("--techniques: " + e.diagnostics()[0].message);
            }
        } else if (std::find(names.begin(), names.end(), t) == names.end()) {
            throw UsageError("--techniques: unknown technique '" + t + "'");
        }
    }
    if ((args.timeSeconds > 0) == (args.iterations > 0))
        throw UsageError("study: give exactly one of --time SECONDS and --iterations N");
    if (!pathExists(args.scene)) throw UsageError("scene file '" + args.scene + "' does not exist");
    if (!args.reference.empty() && !isRegularFile(args.reference))
        throw UsageError("--reference: file '" + args.reference + "' does not exist");
    const fs::path dir(args.outDir);
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (!isDirectory(dir) || ::access(dir.c_str(), W_OK) != 0)
        throw UsageError("--out: cannot write to folder '" + args.outDir + "'");
    std::unique_ptr<tbb::global_control> threadLimit;
    if (args.render.threads > 0)
        threadLimit = std::make_unique<tbb::global_control>(
            tbb::global_control::max_allowed_parallelism, size_t(args.render.threads));

    std::unique_ptr<Scene> scene = loadSceneFile(args.scene, args.render.defines);
    if (!args.render.resolution.empty()) {
        int w = 0, h = 0;
        parseResolution(args.render.resolution, &w, &h);
        scene->camera = scene->camera.resized(w, h, scene->settings.keepHorizontalFov);
    }
    RenderArgs ra = args.render;
    ra.algorithm = "upbp";
    ra.algorithmGiven = true;
    const RenderOptions base = makeRenderOptions(ra, *scene);
    installStopSignalHandlers();

    // ---- the reference ----
    Image ref;
    std::string referenceNote;
    if (!args.reference.empty()) {
        ref = readExr(args.reference);
        if (ref.width != scene->camera.width() || ref.height != scene->camera.height())
            throw UsageError("--reference: '" + args.reference + "' is " +
                             std::to_string(ref.width) + "x" + std::to_string(ref.height) +
                             " but the study renders " + std::to_string(scene->camera.width()) +
                             "x" + std::to_string(scene->camera.height()) +
                             " (set --resolution to match)");
        referenceNote = args.reference;
    } else {
        const double refSeconds =
            args.referenceSeconds > 0 ? args.referenceSeconds : 4.0 * args.timeSeconds;
        const int refIterations = args.referenceSeconds > 0 ? 0 : 4 * args.iterations;
        std::fprintf(stderr,
                     "study: no --reference given: rendering one with upbp for %s "
                     "(DIR/reference.exr); its own noise adds to every error below\n",
                     refIterations > 0 ? (std::to_string(refIterations) + " iterations").c_str()
                                       : fmt("%g s", refSeconds).c_str());
        RenderOptions o = base;
        o.algorithm = "upbp";
        o.seed = base.seed + 1000003;  // independent of the techniques' streams
        TechniqueRun r = runTechnique(*scene, o, refSeconds, refIterations, nullptr, "reference");
        ref = r.image;
        referenceNote = "rendered by this study with upbp, " + std::to_string(r.iterations) +
                        " iterations in " + fmt("%.1f s", r.seconds) + ", seed " +
                        std::to_string(o.seed);
        writeExr((dir / "reference.exr").string(), ref);
    }
    writePng((dir / "reference.png").string(), ref);

    // ---- the techniques ----
    std::vector<TechniqueRun> runs;
    std::ofstream csv(dir / "convergence.csv");
    csv << "technique,iteration,seconds,rmse,relmse,mae\n";
    for (const std::string& t : args.techniques) {
        RenderOptions o = base;
        o.algorithm = t;
        TechniqueRun r = runTechnique(*scene, o, args.timeSeconds, args.iterations, &ref, t);
        for (const Checkpoint& c : r.checkpoints)
            csv << t << "," << c.iteration << "," << fmt("%.6g", c.seconds) << ","
                << fmt("%.8g", c.error.rmseAll) << "," << fmt("%.8g", c.error.relMseAll) << ","
                << fmt("%.8g", c.error.maeAll) << "\n";
        writeImages(dir, r, ref);
        const ImageError& e = r.checkpoints.back().error;
        std::fprintf(stderr, "study: %s: %d iterations in %.1f s, RMSE %.4g, relMSE %.4g\n",
                     t.c_str(), r.iterations, r.seconds, e.rmseAll, e.relMseAll);
        runs.push_back(std::move(r));
    }
    csv.close();
    std::ofstream summary(dir / "summary.csv");
    summary << "technique,iterations,seconds,seconds_per_iteration,rmse,relmse,mae,slope\n";
    for (const TechniqueRun& r : runs) {
        const ImageError& e = r.checkpoints.back().error;
        summary << r.technique << "," << r.iterations << "," << fmt("%.6g", r.seconds) << ","
                << fmt("%.6g", r.seconds / std::max(1, r.iterations)) << ","
                << fmt("%.8g", e.rmseAll) << "," << fmt("%.8g", e.relMseAll) << ","
                << fmt("%.8g", e.maeAll) << ","
                << (std::isfinite(r.slope) ? fmt("%.4f", r.slope) : std::string("nan")) << "\n";
    }
    summary.close();

    // ---- the plot (matplotlib, Debian's python3-matplotlib) ----
    const fs::path script = dir / ".study_plot.py";
    {
        std::ofstream s(script);
        s << kStudyPlotScript;
    }
    // Debian's python3 first (scripts/setup.sh installs python3-matplotlib for it), then
    // whatever python3 the PATH holds.
    std::string plotOutput;
    int status = -1;
    for (const char* python : {"/usr/bin/python3", "python3"}) {
        if (python[0] == '/' && !pathExists(python)) continue;
        const std::string cmd =
            std::string(python) + " '" + script.string() + "' '" + dir.string() + "' 2>&1";
        plotOutput.clear();
        if (FILE* p = ::popen(cmd.c_str(), "r")) {
            char buf[256];
            while (std::fgets(buf, sizeof(buf), p)) plotOutput += buf;
            status = ::pclose(p);
        }
        if (status == 0) break;
    }
    fs::remove(script, ec);
    const bool havePlot = status == 0 && isRegularFile(dir / "convergence.png");
    std::string plotNote;
    if (!havePlot) {
        plotNote =
            "drawing it failed (python3 with matplotlib is needed; scripts/setup.sh "
            "installs python3-matplotlib): " +
            plotOutput;
        std::fprintf(stderr, "study: warning: no convergence plot: %s\n", plotNote.c_str());
    }
    writeReport(dir, args, *scene, base, runs, referenceNote, havePlot, plotNote);
    std::fprintf(stderr, "study: wrote %s (open it in a browser), convergence.csv, summary.csv%s\n",
                 (dir / "index.html").c_str(), havePlot ? ", convergence.png" : "");
    return 0;
}

}  // namespace ub::app
