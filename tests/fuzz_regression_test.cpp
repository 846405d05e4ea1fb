// Regression tests of the fuzzing findings (docs/fuzzing.md): every input committed under
// tests/data/fuzz-regressions/<target>/ is given to the `unibeam` program the way its fuzz
// target gives it to the loader (fuzz/*.cpp): scene files directly, meshes and images through
// a one-shape JSON scene that references them. Each must end as documented: exit status 2 with
// a message naming the file (and the location, where the format has one) and what was
// expected, or, for findings in third-party code, a clean load. scripts/fuzz.sh also replays
// the same inputs under the sanitizers. Every file in the folder must have a case here.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

const fs::path kRegressions = fs::path(UNIBEAM_TEST_DATA_DIR) / "fuzz-regressions";

std::string readFile(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

void writeFile(const fs::path& p, const std::string& s) {
    std::ofstream f(p, std::ios::binary);
    f << s;
}

/// The input split at NUL bytes into `parts` files (fuzz/fuzz_common.h, splitParts).
std::vector<std::string> splitParts(const std::string& data, size_t parts) {
    std::vector<std::string> out(parts);
    size_t part = 0;
    for (char c : data) {
        if (c == '\0' && part + 1 < parts) {
            ++part;
            continue;
        }
        out[part].push_back(c);
    }
    return out;
}

struct CliRun {
    int exitCode = -1;
    std::string err;
};

CliRun runInfo(const fs::path& scene, const fs::path& dir) {
    const fs::path err = dir / "stderr.txt";
    const std::string cmd = std::string("'") + UNIBEAM_BINARY + "' info '" + scene.string() +
                            "' >/dev/null 2>'" + err.string() + "' </dev/null";
    const int status = std::system(cmd.c_str());
    CliRun r;
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.err = readFile(err);
    return r;
}

/// A JSON scene with one shape or texture referencing `file` (relative to the scene).
std::string sceneWith(const std::string& shapeOrMaterial) {
    return R"({"camera": {"position": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0], "fov": 40,
               "resolution": [8, 8]},
  )" + shapeOrMaterial +
           "}\n";
}

/// Prepares the input of `target` in dir as the fuzz target does; returns the file to load.
fs::path prepare(const std::string& target, const std::string& data, const fs::path& dir) {
    if (target == "fuzz_json_scene") {
        writeFile(dir / "fuzz.json", data);
        return dir / "fuzz.json";
    }
    if (target == "fuzz_mitsuba_scene") {
        const auto parts = splitParts(data, 2);
        writeFile(dir / "main.xml", parts[0]);
        writeFile(dir / "inc.xml", parts[1]);
        const fs::path mitsuba = fs::path(UNIBEAM_TEST_DATA_DIR) / "mitsuba";
        fs::create_directory_symlink(mitsuba / "textures", dir / "textures");
        fs::create_directory_symlink(mitsuba / "volumes", dir / "volumes");
        return dir / "main.xml";
    }
    if (target == "fuzz_smallupbp_scene") {
        const auto parts = splitParts(data, 3);
        writeFile(dir / "scene.obj", parts[0]);
        writeFile(dir / "scene.obj.aux", parts[1]);
        writeFile(dir / "scene.mtl", parts[2]);
        return dir / "scene.obj";
    }
    const std::string light =
        R"({"type": "sphere", "radius": 0.5, "emission": [1, 1, 1], "transform": {"translate": [0, 0, 3]}})";
    if (target == "fuzz_mesh_obj" || target == "fuzz_mesh_ply") {
        const std::string ext = target == "fuzz_mesh_obj" ? "obj" : "ply";
        writeFile(dir / ("mesh." + ext), data);
        writeFile(dir / "scene.json",
                  sceneWith(R"("materials": {"m": {"type": "diffuse", "reflectance": 0.5}}, )"
                            R"("shapes": [{"type": ")" +
                            ext + R"(", "file": "mesh.)" + ext + R"(", "material": "m"}, )" +
                            light + "]"));
        return dir / "scene.json";
    }
    // Image targets: the file as a diffuse bitmap texture of a cube.
    auto bitmapScene = [&](const std::string& ext, const std::string& bytes) {
        writeFile(dir / ("image." + ext), bytes);
        writeFile(
            dir / "scene.json",
            sceneWith(
                R"("materials": {"m": {"type": "diffuse", "reflectance": {"type": "bitmap", "file": "image.)" +
                ext + R"("}}}, "shapes": [{"type": "cube", "material": "m"}, )" + light + "]"));
        return dir / "scene.json";
    };
    if (target == "fuzz_png_image" || target == "fuzz_exr_image")
        return bitmapScene(target == "fuzz_png_image" ? "png" : "exr", data);
    if (target == "fuzz_stb_image") {
        // The target's first byte chooses the extension (% 4: bmp, tga, hdr, ppm).
        static const char* const kExt[4] = {"bmp", "tga", "hdr", "ppm"};
        if (data.empty()) return bitmapScene("bmp", data);
        return bitmapScene(kExt[uint8_t(data[0]) % 4], data.substr(1));
    }
    if (target == "fuzz_serialized_mesh") {
        // The target picks shape index size % 3; a Mitsuba scene does so explicitly.
        writeFile(dir / "mesh.serialized", data);
        writeFile(dir / "scene.xml",
                  "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"><film "
                  "type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer "
                  "name=\"height\" value=\"8\"/></film></sensor>\n<emitter "
                  "type=\"constant\"/>\n<shape type=\"serialized\"><string name=\"filename\" "
                  "value=\"mesh.serialized\"/><integer name=\"shape_index\" value=\"" +
                      std::to_string(data.size() % 3) + "\"/></shape>\n</scene>\n");
        return dir / "scene.xml";
    }
    ADD_FAILURE() << "no way to give the CLI an input of target " << target;
    return {};
}

struct Case {
    std::string target, file;
    int exitCode;                       ///< 2: an error; 0: loads (a third-party finding)
    std::vector<std::string> messages;  ///< parts the error message must contain
};

const std::vector<Case> kCases = {
    // readPng allocated the pixels the header announced (here 30000 x 8000) before reading
    // any: a 74-byte file cost 720 MB.
    {"fuzz_png_image",
     "huge-header-tiny-data.png",
     2,
     {"scene.json:3:",
      "cannot read bitmap 'image.png': corrupt PNG image: 30000 x 8000 pixels "
      "need 720008000 bytes of image data, more than the 74 bytes of the file can hold (expected "
      "the image data of every pixel the header announces)"}},
    // libpng allocated what an ancillary chunk announced before reading it: 239 bytes
    // announcing a 973 MB tEXt chunk took 1.1 GB (the memory growth of the earlier runs).
    {"fuzz_png_image",
     "huge-text-chunk.png",
     2,
     {"scene.json:3:",
      "cannot read bitmap 'image.png': corrupt PNG image: chunk 'tEXt' at byte 106 announces "
      "973078564 bytes, more than the 121 bytes left in the file (truncated or corrupt file?)"}},
    // OpenEXR allocated what a header attribute announced (here 1.6 GB) before reading it.
    {"fuzz_exr_image",
     "huge-attribute.exr",
     2,
     {"scene.json:3:", "cannot read bitmap 'image.exr': corrupt OpenEXR image: header attribute",
      "announces 1634231040 bytes, more than the 496 bytes left in the file"}},
    // OpenEXR read a channel name running past the end of the channel list attribute (4.5 KB
    // file, a mutation of a reference image; CI's fuzz run, 2026-12-04) on into the following
    // attributes and sized its buffers from the garbage: 2 GB. The channel list is walked first.
    {"fuzz_exr_image",
     "chlist-name-past-attribute.exr",
     2,
     {"scene.json:3:",
      "cannot read bitmap 'image.exr': corrupt OpenEXR image: the channel list attribute ends "
      "inside a channel entry"}},
    // The same under another attribute name ("chann\x92ls"): OpenEXR parses by type, so the
    // check does too (the local fuzz run after the first fix, 2.6 KB, 2 GB).
    {"fuzz_exr_image",
     "chlist-under-another-name.exr",
     2,
     {"scene.json:3:",
      "cannot read bitmap 'image.exr': corrupt OpenEXR image: the channel list attribute ends "
      "inside a channel entry"}},
    // OpenEXR reads a known type's attribute by its type and goes on from where that read
    // stops, not from the announced end: a channel list without its closing empty name inside
    // the attribute (2.9 KB, a mutation of a reference image) and a float attribute announcing
    // 16,464 bytes (3.2 KB) made it parse the rest as other attributes, one announcing 1.9 and
    // 1.6 GB (CI's fuzz run at a675f59, 2026-12-06, and local runs with seeds 1 and 11 and a
    // 320 MB allocation limit).
    {"fuzz_exr_image",
     "chlist-without-end.exr",
     2,
     {"scene.json:3:",
      "cannot read bitmap 'image.exr': corrupt OpenEXR image: the channel list attribute does "
      "not end with an empty channel name within its size"}},
    {"fuzz_exr_image",
     "float-attribute-wrong-size.exr",
     2,
     {"scene.json:3:", "cannot read bitmap 'image.exr': corrupt OpenEXR image: header attribute '",
      "' (float) has 16464 bytes, expected 4"}},
    // readExr allocated the pixels of the data window (12033 x 12033, 1.7 GB) before reading
    // any from a 20 KB file. Its data window attribute also announces 14,864 bytes, which the
    // attribute check now stops first; the window check is tested by
    // JsonLoaderErrors.ImageHeaderWithAbsurdSizeIsAnError.
    {"fuzz_exr_image",
     "huge-window-small-file.exr",
     2,
     {"scene.json:3:",
      "cannot read bitmap 'image.exr': corrupt OpenEXR image: header attribute 'dataWindow' "
      "(box2i) has 14864 bytes, expected 16"}},
    // PLY, first read through Assimp 5.2 behind a header check, now by unibeam's own reader
    // (scene/ply_reader.h). Assimp leaked on this malformed ASCII body; the reader names the
    // value that is no number.
    {"fuzz_mesh_ply",
     "assimp-leak-malformed-ascii-body.ply",
     2,
     {"mesh.ply:12:3: error: at /shapes/0: PLY value 'i' of property 'y' of 'vertex' element 2 "
      "(expected a float number)",
      "scene.json:3:", "mesh file 'mesh.ply' could not be loaded"}},
    // Assimp tried to allocate 30 GB for a face whose uchar list count reads
    // 41015555555555555555555555555555555555555555 (CI's fuzz run, out-of-memory); the header
    // of this input already lacks a 'y' property, and counts are checked against their type
    // (tests/mesh_io_test.cpp ErrorPlyBadValuesAndCounts).
    {"fuzz_mesh_ply",
     "assimp-oom-ascii-list-count.ply",
     2,
     {"mesh.ply:4: error: at /shapes/0: PLY element 'vertex' has no 'y' property (expected "
      "float properties x, y and z)"}},
    // The reader's own first finding (UBSan): a negative int32 list count in a binary body
    // was converted to an unsigned count. Negative counts are errors; this input's header
    // already has a second format line.
    {"fuzz_mesh_ply",
     "negative-binary-list-count.ply",
     2,
     {"mesh.ply:3: error: at /shapes/0: PLY header has a second 'format' line (expected one, "
      "on line 2)"}},
    // Hangs: Assimp 5.2 looked for end_header for ever when a file starting with "ply" (any
    // case) had none, and it crashed (SEGV) on a header line it could not read. The reader
    // reports a missing end_header, any line that is not PLY's, and a first line that is not
    // exactly "ply".
    {"fuzz_mesh_ply",
     "hang-valid-lines-no-end-header.ply",
     2,
     {"mesh.ply:5: error: at /shapes/0: PLY header has no 'end_header' line (expected the "
      "element and property lines to end with 'end_header'; truncated or corrupt file?)",
      "scene.json:3:", "mesh file 'mesh.ply' could not be loaded"}},
    {"fuzz_mesh_ply",
     "hang-header-without-end-header.ply",
     2,
     {"mesh.ply:3: error: at /shapes/0: unknown PLY header line 'elem%nt vert",
      "(expected format, element, property, comment, obj_info or end_header)"}},
    {"fuzz_mesh_ply",
     "hang-magic-then-nul-bytes.ply",
     2,
     {"mesh.ply:1: error: at /shapes/0: not a PLY file: the first line is 'ply???"}},
    {"fuzz_mesh_ply",
     "hang-mixed-case-magic.ply",
     2,
     {"mesh.ply:1: error: at /shapes/0: not a PLY file: the first line is 'plY' (expected "
      "'ply')"}},
    {"fuzz_mesh_ply",
     "hang-end-header-vertical-tab.ply",
     2,
     {"mesh.ply:15:11: error: at /shapes/0: PLY header line has control character 0x0b at "
      "column 11 (expected header lines of printable text, words separated by spaces)"}},
    {"fuzz_mesh_ply",
     "assimp-segv-bad-format-line.ply",
     2,
     {"mesh.ply:2: error: at /shapes/0: PLY format 'binary_comment' (expected ascii, "
      "binary_little_endian or binary_big_endian)"}},
    // Heap overflow: tinyobjloader reads "f 3/ 2/1 3/1" as corner 3/2, texture coordinate 2 of
    // 1, which validateObj had read as a vertex-only corner; the loader indexed past the array.
    {"fuzz_mesh_obj",
     "corner-with-trailing-slash.obj",
     2,
     {"mesh.obj:10:4: error: at /shapes/0: face corner '3/' ends with '/' (expected v, v/vt, "
      "v//vn or v/vt/vn)",
      "scene.json:3:", "mesh file 'mesh.obj' could not be loaded"}},
    // Uncaught std::filesystem::filesystem_error: an mtllib name of 300 bytes made the
    // one-argument is_regular_file throw ENAMETOOLONG (loaders now ask core/file_status.h).
    {"fuzz_smallupbp_scene",
     "mtllib-name-too-long.obj",
     2,
     {"scene.obj:1:8: error: material library '", "not found (looked for '"}},
    // UBSan (pointer overflow): a shape dictionary entry of 2^64 - 1 wrapped the bound check
    // (offset + 4 > end) and was used as the shape's offset.
    {"fuzz_serialized_mesh",
     "dictionary-offset-wraps.serialized",
     2,
     {"invalid .serialized file: the dictionary gives shape 1 the offset 18446744073709551615, "
      "outside the file's shape data"}},
    // Heap overflow in stb_image (libstb-dev 0.0~git20220908): a 16-bit grey PNM converted to
    // 3 channels by stb read past its buffer. readStbImage asks for the file's own channels,
    // and RGBE data must match the extension: under a .hdr name this is no RGBE file, under
    // a .ppm name it decodes (a 3 x 525 header with no room for its pixels: truncated).
    {"fuzz_stb_image",
     "pnm16-under-hdr-name.bin",
     2,
     {"scene.json:3:", "cannot read bitmap 'image.hdr'", "not a Radiance RGBE file"}},
    {"fuzz_stb_image", "pnm16-to-rgb.bin", 2, {"scene.json:3:", "cannot read bitmap 'image.ppm'"}},
    // UBSan: stb_image read the PNM height 54444444444444444444444444446 into an int (signed
    // overflow). Header numbers of more than 9 digits are errors before stb parses them.
    {"fuzz_stb_image",
     "pnm-header-int-overflow.bin",
     2,
     {"scene.json:3:", "cannot read bitmap 'image.ppm'",
      "PNM header height has 29 digits (expected at most 9)"}},
    // Hang (CI's fuzz run, a timeout): stb_image's run-length RGBE decoder loops for ever on
    // a packet of count 0, which is what it reads past the end of a truncated file.
    {"fuzz_stb_image",
     "rgbe-rle-truncated-hang.bin",
     2,
     {"scene.json:3:", "cannot read bitmap 'image.hdr'",
      "the image data ends before the image does (truncated file; in the run-length data of "
      "row 0)"}},
    // Out of memory (fuzz_stb_image with long inputs): stbi_info gives a top-down BMP's
    // height negative, so the signed pixel count passed the size bound, and stb allocated
    // 8192 x 50527 x 3 bytes for a 31-byte file.
    {"fuzz_stb_image",
     "bmp-negative-height-1gb.bin",
     2,
     {"scene.json:3:", "cannot read bitmap 'image.bmp'",
      "the header announces 8192 x 50527 pixels, more than a 31-byte file can hold"}},
    // A seed (tests/data/mitsuba/media.xml with its include): UBSan's alignment check in
    // oneTBB's concurrent_hash_map under OpenVDB (fuzz/ubsan_ignorelist.txt); it loads.
    {"fuzz_mitsuba_scene", "tbb-hash-map-sentinel-downcast.xml", 0, {}},
};

}  // namespace

TEST(FuzzRegressions, EveryInputEndsAsDocumented) {
    std::set<std::string> covered;
    for (const Case& c : kCases) {
        SCOPED_TRACE(c.target + "/" + c.file);
        const fs::path input = kRegressions / c.target / c.file;
        ASSERT_TRUE(fs::is_regular_file(input)) << input;
        covered.insert((fs::path(c.target) / c.file).string());
        const fs::path dir = fs::temp_directory_path() /
                             ("unibeam_fuzzreg_" + c.file + "_" + std::to_string(::getpid()));
        fs::remove_all(dir);
        fs::create_directories(dir);
        const fs::path scene = prepare(c.target, readFile(input), dir);
        const CliRun r = runInfo(scene, dir);
        EXPECT_EQ(r.exitCode, c.exitCode) << r.err;
        for (const std::string& m : c.messages)
            EXPECT_NE(r.err.find(m), std::string::npos) << "expected '" << m << "' in:\n" << r.err;
        fs::remove_all(dir);
    }
    // Every committed input has a case.
    for (const auto& target : fs::directory_iterator(kRegressions))
        for (const auto& f : fs::directory_iterator(target.path())) {
            const std::string key =
                (fs::path(target.path().filename()) / f.path().filename()).string();
            EXPECT_TRUE(covered.count(key)) << "no case for " << key;
        }
}
