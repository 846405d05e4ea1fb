// Catalogue of malformed inputs, end to end: each case writes a small scene (and the files it
// references) into a fresh folder and runs `unibeam info` on it. Every case must exit with
// status 2 and print the loader's first diagnostic exactly as listed: the file it is in, the
// location (line:column for text formats, the JSON path of the referencing key for meshes and
// images, which have no lines) and what was expected. Cases cover every loader: native JSON
// (16), Mitsuba XML with includes (12), .vol grids (5), SmallUPBP .obj/.mtl/.aux (7), OBJ (4)
// and PLY (4) meshes, Mitsuba .serialized meshes (3), PNG (2), JPEG (2) and OpenEXR (2) images, and
// the CLI's own scene checks (2). Earlier CLI cases (tests/cli_test.cpp, MissingOrBadSceneExitsTwo:
// a missing scene for render and info, a JSON syntax error) are not repeated; the loaders' own
// tests check the same kinds of errors in-process. File contents "@data:PATH" are copied from
// tests/data,
// "@prefix:N:PATH" are the first N bytes of a repository file (a truncated image).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace {

namespace fs = std::filesystem;

struct Case {
    const char* name;
    std::vector<std::pair<std::string, std::string>> files;  ///< name, contents
    std::string main;                                        ///< the file given to `info`
    std::vector<std::string> args;                           ///< extra arguments
    std::string firstDiagnostic;  ///< first stderr line, folder prefixes removed
};

// clang-format off
const std::vector<Case> kCases = {
    {"json_syntax_trailing_comma",
     {{"s.json", "{\"camera\": {\"fov\": 40,},\n"
            "}\n"}},
     "s.json",
     {},
     "s.json:1:23: error: invalid JSON: syntax error while parsing object key - unexpected '}'; expected string literal"},
    {"json_unknown_top_key",
     {{"s.json", "{\n"
            "\"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 40, \"resolution\": [8, 8]},\n"
            "\"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5}},\n"
            "\"shapes\": [\n"
            "{\"type\": \"cube\", \"material\": \"m\"},\n"
            "{\"type\": \"sphere\", \"radius\": 0.5, \"emission\": [1, 1, 1], \"transform\": {\"translate\": [0, 0, 3]}}\n"
            "],\n"
            "\"lights_extra\": 1\n"
            "}\n"}},
     "s.json",
     {},
     "s.json:8:1: error: at /lights_extra: unknown key 'lights_extra' in the scene; valid keys: description, camera, settings, materials, media, medium, sha"},
    {"json_fov_out_of_range",
     {{"s.json", "{\n"
            "\"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 200, \"resolution\": [8, 8]},\n"
            "\"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5}},\n"
            "\"shapes\": [\n"
            "{\"type\": \"cube\", \"material\": \"m\"},\n"
            "{\"type\": \"sphere\", \"radius\": 0.5, \"emission\": [1, 1, 1], \"transform\": {\"translate\": [0, 0, 3]}}\n"
            "]\n"
            "}\n"}},
     "s.json",
     {},
     "s.json:2:80: error: at /camera/fov: expected a number in (0, 180), got 200"},
    {"json_resolution_zero",
     {{"s.json", "{\n"
            "\"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 40, \"resolution\": [0, 8]},\n"
            "\"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5}},\n"
            "\"shapes\": [\n"
            "{\"type\": \"cube\", \"material\": \"m\"},\n"
            "{\"type\": \"sphere\", \"radius\": 0.5, \"emission\": [1, 1, 1], \"transform\": {\"translate\": [0, 0, 3]}}\n"
            "]\n"
            "}\n"}},
     "s.json",
     {},
     "s.json:2:99: error: at /camera/resolution/0: expected an integer in [1, 16384], got 0"},
    {"json_unknown_material_type",
     {{"s.json", "{\n"
            "\"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 40, \"resolution\": [8, 8]},\n"
            "\"materials\": {\"m\": {\"type\": \"velvet\"}},\n"
            "\"shapes\": [\n"
            "{\"type\": \"cube\", \"material\": \"m\"},\n"
            "{\"type\": \"sphere\", \"radius\": 0.5, \"emission\": [1, 1, 1], \"transform\": {\"translate\": [0, 0, 3]}}\n"
            "]\n"
            "}\n"}},
     "s.json",
     {},
     "s.json:3:29: error: at /materials/m/type: unknown material type 'velvet'; valid types: diffuse, phong, mirror, dielectric, rough_conductor, rough_diel"},
    {"json_undefined_material",
     {{"s.json", "{\n"
            "\"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 40, \"resolution\": [8, 8]},\n"
            "\"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5}},\n"
            "\"shapes\": [\n"
            "{\"type\": \"cube\", \"material\": \"nope\"},\n"
            "{\"type\": \"sphere\", \"radius\": 0.5, \"emission\": [1, 1, 1], \"transform\": {\"translate\": [0, 0, 3]}}\n"
            "]\n"
            "}\n"}},
     "s.json",
     {},
     "s.json:5:30: error: at /shapes/0/material: unknown material 'nope' (defined: m)"},
    {"json_number_overflow",
     {{"s.json", "{\n"
            "\"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 40, \"resolution\": [8, 8]},\n"
            "\"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5}},\n"
            "\"shapes\": [\n"
            "{\"type\": \"sphere\", \"radius\": 1e999, \"material\": \"m\"},\n"
            "{\"type\": \"sphere\", \"radius\": 0.5, \"emission\": [1, 1, 1], \"transform\": {\"translate\": [0, 0, 3]}}\n"
            "]\n"
            "}\n"}},
     "s.json",
     {},
     "s.json:5:30: error: invalid number: number overflow parsing '1e999' (expected a finite number)"},
    {"json_missing_camera",
     {{"s.json", "{\n"
            "\"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5}},\n"
            "\"shapes\": [{\"type\": \"sphere\", \"radius\": 0.5, \"emission\": [1, 1, 1], \"transform\": {\"translate\": [0, 0, 3]}}]\n"
            "}\n"}},
     "s.json",
     {},
     "s.json:1:1: error: at /camera: missing required key 'camera' (expected a camera object with \"position\" and \"target\")"},
    {"json_no_light",
     {{"s.json", "{\n"
            "\"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 40, \"resolution\": [8, 8]},\n"
            "\"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5}},\n"
            "\"shapes\": [\n"
            "{\"type\": \"cube\", \"material\": \"m\"}\n"
            "]\n"
            "}\n"}},
     "s.json",
     {},
     "s.json:1:1: error: at /: the scene has no light (expected an entry in \"lights\" or a shape with an \"emission\")"},
    {"json_radius_wrong_type",
     {{"s.json", "{\n"
            "\"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 40, \"resolution\": [8, 8]},\n"
            "\"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5}},\n"
            "\"shapes\": [\n"
            "{\"type\": \"sphere\", \"radius\": \"big\", \"material\": \"m\"},\n"
            "{\"type\": \"sphere\", \"radius\": 0.5, \"emission\": [1, 1, 1], \"transform\": {\"translate\": [0, 0, 3]}}\n"
            "]\n"
            "}\n"}},
     "s.json",
     {},
     "s.json:5:30: error: at /shapes/0/radius: expected a number > 0, got a string (\"big\")"},
    {"json_unknown_shape_type",
     {{"s.json", "{\n"
            "\"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 40, \"resolution\": [8, 8]},\n"
            "\"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5}},\n"
            "\"shapes\": [\n"
            "{\"type\": \"torus\", \"material\": \"m\"},\n"
            "{\"type\": \"sphere\", \"radius\": 0.5, \"emission\": [1, 1, 1], \"transform\": {\"translate\": [0, 0, 3]}}\n"
            "]\n"
            "}\n"}},
     "s.json",
     {},
     "s.json:5:10: error: at /shapes/0/type: unknown shape type 'torus'; valid types: obj, ply, rectangle, cube, sphere, disk, cylinder"},
    {"json_missing_mesh_file",
     {{"s.json", "{\n"
            "\"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 40, \"resolution\": [8, 8]},\n"
            "\"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5}},\n"
            "\"shapes\": [\n"
            "{\"type\": \"obj\", \"file\": \"missing.obj\", \"material\": \"m\"},\n"
            "{\"type\": \"sphere\", \"radius\": 0.5, \"emission\": [1, 1, 1], \"transform\": {\"translate\": [0, 0, 3]}}\n"
            "]\n"
            "}\n"}},
     "s.json",
     {},
     "s.json:5:25: error: at /shapes/0/file: mesh file 'missing.obj' not found (looked for 'missing.obj'; paths are relative to the scene file)"},
    {"json_missing_bitmap",
     {{"s.json", "{\n"
            "\"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 40, \"resolution\": [8, 8]},\n"
            "\"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": {\"type\": \"bitmap\", \"file\": \"missing.png\"}}},\n"
            "\"shapes\": [\n"
            "{\"type\": \"cube\", \"material\": \"m\"},\n"
            "{\"type\": \"sphere\", \"radius\": 0.5, \"emission\": [1, 1, 1], \"transform\": {\"translate\": [0, 0, 3]}}\n"
            "]\n"
            "}\n"}},
     "s.json",
     {},
     "s.json:3:82: error: at /materials/m/reflectance/file: bitmap 'missing.png' not found (looked for 'missing.png'; paths are relative to the scene file)"},
    {"json_negative_sigma",
     {{"s.json", "{\n"
            "\"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 40, \"resolution\": [8, 8]},\n"
            "\"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5}},\n"
            "\"shapes\": [\n"
            "{\"type\": \"cube\", \"interior_medium\": \"fog\", \"material\": \"m\"},\n"
            "{\"type\": \"sphere\", \"radius\": 0.5, \"emission\": [1, 1, 1], \"transform\": {\"translate\": [0, 0, 3]}}\n"
            "],\n"
            "\"media\": {\"fog\": {\"type\": \"homogeneous\", \"sigma_a\": -1, \"sigma_s\": 1}}\n"
            "}\n"}},
     "s.json",
     {},
     "s.json:8:53: error: at /media/fog/sigma_a: expected a number >= 0, got -1"},
    {"json_reflectance_above_one",
     {{"s.json", "{\n"
            "\"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 40, \"resolution\": [8, 8]},\n"
            "\"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 1.5}},\n"
            "\"shapes\": [\n"
            "{\"type\": \"cube\", \"material\": \"m\"},\n"
            "{\"type\": \"sphere\", \"radius\": 0.5, \"emission\": [1, 1, 1], \"transform\": {\"translate\": [0, 0, 3]}}\n"
            "]\n"
            "}\n"}},
     "s.json",
     {},
     "s.json:3:55: error: at /materials/m/reflectance: expected a number in [0, 1], got 1.5"},
    {"json_not_an_object",
     {{"s.json", "[1, 2, 3]\n"}},
     "s.json",
     {},
     "s.json:1:1: error: at /: expected a scene object with \"camera\", \"materials\", \"shapes\" ..., got an array ([1,2,3])"},
    {"xml_unclosed_tag",
     {{"s.xml", "<scene version=\"3.0.0\">\n"
            "    <sensor type=\"perspective\">\n"
            "        <float name=\"fov\" value=\"40\"/>\n"
            "        <film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/></film>\n"
            "    </sensor>\n"
            "    <shape type=\"sphere\">\n"
            "</scene>\n"}},
     "s.xml",
     {},
     "s.xml:7:3: error: invalid XML: Start-end tags mismatch"},
    {"xml_unsupported_bsdf",
     {{"s.xml", "<scene version=\"3.0.0\">\n"
            "    <sensor type=\"perspective\">\n"
            "        <float name=\"fov\" value=\"40\"/>\n"
            "        <film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/></film>\n"
            "    </sensor>\n"
            "    <emitter type=\"constant\"/>\n"
            "    <shape type=\"sphere\"><bsdf type=\"velvet\"/></shape>\n"
            "</scene>\n"}},
     "s.xml",
     {},
     "s.xml:7:26: error: unsupported bsdf plugin 'velvet' (supported: diffuse, conductor, roughconductor, dielectric, roughdielectric, thindielectric, plast"},
    {"xml_unknown_parameter",
     {{"s.xml", "<scene version=\"3.0.0\">\n"
            "    <sensor type=\"perspective\">\n"
            "        <float name=\"fov\" value=\"40\"/>\n"
            "        <film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/></film>\n"
            "    </sensor>\n"
            "    <emitter type=\"constant\"/>\n"
            "    <shape type=\"sphere\"><float name=\"wobble\" value=\"1\"/></shape>\n"
            "</scene>\n"}},
     "s.xml",
     {},
     "s.xml:7:26: error: <shape type=\"sphere\">: unsupported parameter 'wobble' (<float>); see docs/mitsuba.md for what unibeam reads"},
    {"xml_no_sensor",
     {{"s.xml", "<scene version=\"3.0.0\">\n"
            "    <emitter type=\"constant\"/>\n"
            "    <shape type=\"sphere\"/>\n"
            "</scene>\n"}},
     "s.xml",
     {},
     "s.xml: error: the scene has no <sensor> (expected one perspective sensor)"},
    {"xml_missing_include",
     {{"s.xml", "<scene version=\"3.0.0\">\n"
            "    <sensor type=\"perspective\">\n"
            "        <float name=\"fov\" value=\"40\"/>\n"
            "        <film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/></film>\n"
            "    </sensor>\n"
            "    <emitter type=\"constant\"/>\n"
            "    <include filename=\"nothere.xml\"/>\n"
            "</scene>\n"}},
     "s.xml",
     {},
     "s.xml:7:5: error: included file 'nothere.xml' not found"},
    {"xml_include_cycle",
     {{"s.xml", "<scene version=\"3.0.0\">\n"
            "    <sensor type=\"perspective\">\n"
            "        <float name=\"fov\" value=\"40\"/>\n"
            "        <film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/></film>\n"
            "    </sensor>\n"
            "    <emitter type=\"constant\"/>\n"
            "    <include filename=\"s.xml\"/>\n"
            "</scene>\n"}},
     "s.xml",
     {},
     "s.xml:7:5: error: include cycle: 's.xml' is already being read (it includes itself, directly or through other files)"},
    {"xml_bad_float",
     {{"s.xml", "<scene version=\"3.0.0\">\n"
            "    <sensor type=\"perspective\">\n"
            "        <float name=\"fov\" value=\"40\"/>\n"
            "        <film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/></film>\n"
            "    </sensor>\n"
            "    <emitter type=\"constant\"/>\n"
            "    <shape type=\"sphere\"><float name=\"radius\" value=\"abc\"/></shape>\n"
            "</scene>\n"}},
     "s.xml",
     {},
     "s.xml:7:26: error: <float> property 'radius': expected a finite number, got 'abc'"},
    {"xml_undefined_param",
     {{"s.xml", "<scene version=\"3.0.0\">\n"
            "    <sensor type=\"perspective\">\n"
            "        <float name=\"fov\" value=\"40\"/>\n"
            "        <film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/></film>\n"
            "    </sensor>\n"
            "    <emitter type=\"constant\"/>\n"
            "    <shape type=\"sphere\"><float name=\"radius\" value=\"$r\"/></shape>\n"
            "</scene>\n"}},
     "s.xml",
     {},
     "s.xml:7:26: error: attribute 'value' uses the undefined parameter '$r' (define it with <default name=\"r\" value=\"...\"/> or -D r=VALUE)"},
    {"xml_rgb_two_values",
     {{"s.xml", "<scene version=\"3.0.0\">\n"
            "    <sensor type=\"perspective\">\n"
            "        <float name=\"fov\" value=\"40\"/>\n"
            "        <film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/></film>\n"
            "    </sensor>\n"
            "    <emitter type=\"constant\"/>\n"
            "    <shape type=\"sphere\"><bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0.5, 0.5\"/></bsdf></shape>\n"
            "</scene>\n"}},
     "s.xml",
     {},
     "s.xml:7:47: error: <rgb> property 'reflectance': expected one or three numbers, got '0.5, 0.5'"},
    {"xml_missing_obj",
     {{"s.xml", "<scene version=\"3.0.0\">\n"
            "    <sensor type=\"perspective\">\n"
            "        <float name=\"fov\" value=\"40\"/>\n"
            "        <film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/></film>\n"
            "    </sensor>\n"
            "    <emitter type=\"constant\"/>\n"
            "    <shape type=\"obj\"><string name=\"filename\" value=\"none.obj\"/></shape>\n"
            "</scene>\n"}},
     "s.xml",
     {},
     "s.xml:7:23: error: <shape type=\"obj\">: file 'none.obj' not found"},
    {"xml_root_not_scene",
     {{"s.xml", "<notscene version=\"3.0.0\"/>\n"}},
     "s.xml",
     {},
     "s.xml:1:1: error: expected a <scene> root element, got <notscene>"},
    {"xml_missing_vol",
     {{"s.xml", "<scene version=\"3.0.0\">\n"
            "    <sensor type=\"perspective\">\n"
            "        <float name=\"fov\" value=\"40\"/>\n"
            "        <film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/></film>\n"
            "    </sensor>\n"
            "    <emitter type=\"constant\"/>\n"
            "    <shape type=\"cube\">\n"
            "        <bsdf type=\"null\"/>\n"
            "        <medium name=\"interior\" type=\"heterogeneous\">\n"
            "            <volume name=\"sigma_t\" type=\"gridvolume\"><string name=\"filename\" value=\"none.vol\"/></volume>\n"
            "        </medium>\n"
            "    </shape>\n"
            "</scene>\n"}},
     "s.xml",
     {},
     "s.xml:10:54: error: <volume type=\"gridvolume\">: file 'none.vol' not found"},
    {"vol_bad_magic",
     {{"s.xml", "<scene version=\"3.0.0\">\n"
            "    <sensor type=\"perspective\">\n"
            "        <float name=\"fov\" value=\"40\"/>\n"
            "        <film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/></film>\n"
            "    </sensor>\n"
            "    <emitter type=\"constant\"/>\n"
            "    <shape type=\"cube\">\n"
            "        <bsdf type=\"null\"/>\n"
            "        <medium name=\"interior\" type=\"heterogeneous\">\n"
            "            <volume name=\"sigma_t\" type=\"gridvolume\"><string name=\"filename\" value=\"g.vol\"/></volume>\n"
            "        </medium>\n"
            "    </shape>\n"
            "</scene>\n"},
      {"g.vol", std::string("VOX\003\001\000\000\000\002\000\000\000\002\000\000\000\002\000\000\000\001\000\000\000\000\000\000\000\000\000\000\000\000\000\000\000\000\000\200?\000\000\200?\000\000\200?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\000?", 80)}},
     "s.xml",
     {},
     "s.xml:10:54: error: <volume type=\"gridvolume\">: g.vol: error: invalid .vol file: missing the 'VOL' magic at the start (not a Mitsuba volume file)"},
    {"vol_version_2",
     {{"s.xml", "<scene version=\"3.0.0\">\n"
            "    <sensor type=\"perspective\">\n"
            "        <float name=\"fov\" value=\"40\"/>\n"
            "        <film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/></film>\n"
            "    </sensor>\n"
            "    <emitter type=\"constant\"/>\n"
            "    <shape type=\"cube\">\n"
            "        <bsdf type=\"null\"/>\n"
            "        <medium name=\"interior\" type=\"heterogeneous\">\n"
            "            <volume name=\"sigma_t\" type=\"gridvolume\"><string name=\"filename\" value=\"g.vol\"/></volume>\n"
            "        </medium>\n"
            "    </shape>\n"
            "</scene>\n"},
      {"g.vol", std::string("VOL\002\001\000\000\000\002\000\000\000\002\000\000\000\002\000\000\000\001\000\000\000\000\000\000\000\000\000\000\000\000\000\000\000\000\000\200?\000\000\200?\000\000\200?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\000?", 80)}},
     "s.xml",
     {},
     "s.xml:10:54: error: <volume type=\"gridvolume\">: g.vol: error: invalid .vol file: version 2 (expected 3)"},
    {"vol_truncated",
     {{"s.xml", "<scene version=\"3.0.0\">\n"
            "    <sensor type=\"perspective\">\n"
            "        <float name=\"fov\" value=\"40\"/>\n"
            "        <film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/></film>\n"
            "    </sensor>\n"
            "    <emitter type=\"constant\"/>\n"
            "    <shape type=\"cube\">\n"
            "        <bsdf type=\"null\"/>\n"
            "        <medium name=\"interior\" type=\"heterogeneous\">\n"
            "            <volume name=\"sigma_t\" type=\"gridvolume\"><string name=\"filename\" value=\"g.vol\"/></volume>\n"
            "        </medium>\n"
            "    </shape>\n"
            "</scene>\n"},
      {"g.vol", std::string("VOL\003\001\000\000\000\002\000\000\000\002\000\000\000\002\000\000\000\001\000\000\000\000\000\000\000\000\000\000\000\000\000\000\000\000\000\200?\000\000\200?\000\000\200?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\000?", 76)}},
     "s.xml",
     {},
     "s.xml:10:54: error: <volume type=\"gridvolume\">: g.vol: error: invalid .vol file: the header announces 2 x 2 x 2 x 1 float32 values (80 bytes with the "},
    {"vol_two_channels",
     {{"s.xml", "<scene version=\"3.0.0\">\n"
            "    <sensor type=\"perspective\">\n"
            "        <float name=\"fov\" value=\"40\"/>\n"
            "        <film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/></film>\n"
            "    </sensor>\n"
            "    <emitter type=\"constant\"/>\n"
            "    <shape type=\"cube\">\n"
            "        <bsdf type=\"null\"/>\n"
            "        <medium name=\"interior\" type=\"heterogeneous\">\n"
            "            <volume name=\"sigma_t\" type=\"gridvolume\"><string name=\"filename\" value=\"g.vol\"/></volume>\n"
            "        </medium>\n"
            "    </shape>\n"
            "</scene>\n"},
      {"g.vol", std::string("VOL\003\001\000\000\000\002\000\000\000\002\000\000\000\002\000\000\000\002\000\000\000\000\000\000\000\000\000\000\000\000\000\000\000\000\000\200?\000\000\200?\000\000\200?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\000?", 112)}},
     "s.xml",
     {},
     "s.xml:10:54: error: <volume type=\"gridvolume\">: g.vol: error: invalid .vol file: 2 channels (expected 1: density, or 3: RGB albedo)"},
    {"vol_nan_value",
     {{"s.xml", "<scene version=\"3.0.0\">\n"
            "    <sensor type=\"perspective\">\n"
            "        <float name=\"fov\" value=\"40\"/>\n"
            "        <film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/></film>\n"
            "    </sensor>\n"
            "    <emitter type=\"constant\"/>\n"
            "    <shape type=\"cube\">\n"
            "        <bsdf type=\"null\"/>\n"
            "        <medium name=\"interior\" type=\"heterogeneous\">\n"
            "            <volume name=\"sigma_t\" type=\"gridvolume\"><string name=\"filename\" value=\"g.vol\"/></volume>\n"
            "        </medium>\n"
            "    </shape>\n"
            "</scene>\n"},
      {"g.vol", std::string("VOL\003\001\000\000\000\002\000\000\000\002\000\000\000\002\000\000\000\001\000\000\000\000\000\000\000\000\000\000\000\000\000\000\000\000\000\200?\000\000\200?\000\000\200?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\000?\000\000\300\177", 80)}},
     "s.xml",
     {},
     "s.xml:10:54: error: <volume type=\"gridvolume\">: g.vol: error: invalid .vol file: non-finite value at voxel (1, 1, 1), channel 0"},
    {"upbp_missing_aux",
     {{"s.obj", "mtllib s.mtl\n"
            "v -1 -1 0\n"
            "v 1 -1 0\n"
            "v 1 1 0\n"
            "v -1 1 0\n"
            "v -0.2 -0.2 2\n"
            "v 0.2 -0.2 2\n"
            "v 0.2 0.2 2\n"
            "usemtl white\n"
            "f 1 2 3\n"
            "f 1 3 4\n"
            "usemtl lamp\n"
            "f 5 7 6\n"},
      {"s.mtl", "newmtl white\n"
            "Kd 0.5 0.5 0.5\n"
            "newmtl lamp\n"
            "Kd 0 0 0\n"}},
     "s.obj",
     {},
     "s.obj: error: an .obj scene is read in SmallUPBP's format, which needs the file 's.obj.aux' beside it (camera, media and lights; see docs/smallupbp.md"},
    {"upbp_missing_mtl",
     {{"s.obj", "mtllib other.mtl\n"
            "v -1 -1 0\n"
            "v 1 -1 0\n"
            "v 1 1 0\n"
            "v -1 1 0\n"
            "v -0.2 -0.2 2\n"
            "v 0.2 -0.2 2\n"
            "v 0.2 0.2 2\n"
            "usemtl white\n"
            "f 1 2 3\n"
            "f 1 3 4\n"
            "usemtl lamp\n"
            "f 5 7 6\n"},
      {"s.obj.aux", "#CAMERA\n"
            "TM_ROW0 1 0 0\n"
            "TM_ROW1 0 1 0\n"
            "TM_ROW2 0 0 1\n"
            "TM_ROW3 0 0 -5\n"
            "CAMERA_FOV 0.7854\n"
            "CAMERA_TDIST 5\n"
            "\n"
            "#MATERIALS\n"
            "\n"
            "material white\n"
            "Kd 0.5 0.5 0.5\n"
            "\n"
            "material lamp\n"
            "Ke 10 10 10\n"},
      {"s.mtl", "newmtl white\n"
            "Kd 0.5 0.5 0.5\n"
            "newmtl lamp\n"
            "Kd 0 0 0\n"}},
     "s.obj",
     {},
     "s.obj:1:8: error: material library 'other.mtl' not found (looked for 'other.mtl'; SmallUPBP reads it from the folder of the .obj)"},
    {"upbp_face_index_out_of_range",
     {{"s.obj", "mtllib s.mtl\n"
            "v -1 -1 0\n"
            "v 1 -1 0\n"
            "v 1 1 0\n"
            "v -1 1 0\n"
            "v -0.2 -0.2 2\n"
            "v 0.2 -0.2 2\n"
            "v 0.2 0.2 2\n"
            "usemtl white\n"
            "f 1 2 3\n"
            "f 1 3 4\n"
            "usemtl lamp\n"
            "f 5 7 99\n"},
      {"s.obj.aux", "#CAMERA\n"
            "TM_ROW0 1 0 0\n"
            "TM_ROW1 0 1 0\n"
            "TM_ROW2 0 0 1\n"
            "TM_ROW3 0 0 -5\n"
            "CAMERA_FOV 0.7854\n"
            "CAMERA_TDIST 5\n"
            "\n"
            "#MATERIALS\n"
            "\n"
            "material white\n"
            "Kd 0.5 0.5 0.5\n"
            "\n"
            "material lamp\n"
            "Ke 10 10 10\n"},
      {"s.mtl", "newmtl white\n"
            "Kd 0.5 0.5 0.5\n"
            "newmtl lamp\n"
            "Kd 0 0 0\n"}},
     "s.obj",
     {},
     "s.obj:13:7: error: vertex index 99 out of range (the file has 7 vertices)"},
    {"upbp_undefined_usemtl",
     {{"s.obj", "mtllib s.mtl\n"
            "v -1 -1 0\n"
            "v 1 -1 0\n"
            "v 1 1 0\n"
            "v -1 1 0\n"
            "v -0.2 -0.2 2\n"
            "v 0.2 -0.2 2\n"
            "v 0.2 0.2 2\n"
            "usemtl white\n"
            "f 1 2 3\n"
            "f 1 3 4\n"
            "usemtl nothing\n"
            "f 5 7 6\n"},
      {"s.obj.aux", "#CAMERA\n"
            "TM_ROW0 1 0 0\n"
            "TM_ROW1 0 1 0\n"
            "TM_ROW2 0 0 1\n"
            "TM_ROW3 0 0 -5\n"
            "CAMERA_FOV 0.7854\n"
            "CAMERA_TDIST 5\n"
            "\n"
            "#MATERIALS\n"
            "\n"
            "material white\n"
            "Kd 0.5 0.5 0.5\n"
            "\n"
            "material lamp\n"
            "Ke 10 10 10\n"},
      {"s.mtl", "newmtl white\n"
            "Kd 0.5 0.5 0.5\n"
            "newmtl lamp\n"
            "Kd 0 0 0\n"}},
     "s.obj",
     {},
     "s.obj:12:8: error: unknown material 'nothing' (the .mtl defines: white, lamp)"},
    {"upbp_aux_bad_number",
     {{"s.obj", "mtllib s.mtl\n"
            "v -1 -1 0\n"
            "v 1 -1 0\n"
            "v 1 1 0\n"
            "v -1 1 0\n"
            "v -0.2 -0.2 2\n"
            "v 0.2 -0.2 2\n"
            "v 0.2 0.2 2\n"
            "usemtl white\n"
            "f 1 2 3\n"
            "f 1 3 4\n"
            "usemtl lamp\n"
            "f 5 7 6\n"},
      {"s.obj.aux", "#CAMERA\n"
            "TM_ROW0 1 0 0\n"
            "TM_ROW1 0 1 0\n"
            "TM_ROW2 0 0 1\n"
            "TM_ROW3 0 0 -5\n"
            "CAMERA_FOV wide\n"
            "CAMERA_TDIST 5\n"
            "\n"
            "#MATERIALS\n"
            "\n"
            "material white\n"
            "Kd 0.5 0.5 0.5\n"
            "\n"
            "material lamp\n"
            "Ke 10 10 10\n"},
      {"s.mtl", "newmtl white\n"
            "Kd 0.5 0.5 0.5\n"
            "newmtl lamp\n"
            "Kd 0 0 0\n"}},
     "s.obj",
     {},
     "s.obj.aux:6:12: error: 'wide' is not a number: 'CAMERA_FOV' expects 1 number (horizontal field of view in radians)"},
    {"upbp_obj_bad_vertex",
     {{"s.obj", "mtllib s.mtl\n"
            "v -1 -1 0\n"
            "v 1 x 0\n"
            "v 1 1 0\n"
            "v -1 1 0\n"
            "v -0.2 -0.2 2\n"
            "v 0.2 -0.2 2\n"
            "v 0.2 0.2 2\n"
            "usemtl white\n"
            "f 1 2 3\n"
            "f 1 3 4\n"
            "usemtl lamp\n"
            "f 5 7 6\n"},
      {"s.obj.aux", "#CAMERA\n"
            "TM_ROW0 1 0 0\n"
            "TM_ROW1 0 1 0\n"
            "TM_ROW2 0 0 1\n"
            "TM_ROW3 0 0 -5\n"
            "CAMERA_FOV 0.7854\n"
            "CAMERA_TDIST 5\n"
            "\n"
            "#MATERIALS\n"
            "\n"
            "material white\n"
            "Kd 0.5 0.5 0.5\n"
            "\n"
            "material lamp\n"
            "Ke 10 10 10\n"},
      {"s.mtl", "newmtl white\n"
            "Kd 0.5 0.5 0.5\n"
            "newmtl lamp\n"
            "Kd 0 0 0\n"}},
     "s.obj",
     {},
     "s.obj:3:5: error: 'x' is not a finite number ('v' expects 3 numbers)"},
    {"upbp_mtl_bad_number",
     {{"s.obj", "mtllib s.mtl\n"
            "v -1 -1 0\n"
            "v 1 -1 0\n"
            "v 1 1 0\n"
            "v -1 1 0\n"
            "v -0.2 -0.2 2\n"
            "v 0.2 -0.2 2\n"
            "v 0.2 0.2 2\n"
            "usemtl white\n"
            "f 1 2 3\n"
            "f 1 3 4\n"
            "usemtl lamp\n"
            "f 5 7 6\n"},
      {"s.obj.aux", "#CAMERA\n"
            "TM_ROW0 1 0 0\n"
            "TM_ROW1 0 1 0\n"
            "TM_ROW2 0 0 1\n"
            "TM_ROW3 0 0 -5\n"
            "CAMERA_FOV 0.7854\n"
            "CAMERA_TDIST 5\n"
            "\n"
            "#MATERIALS\n"
            "\n"
            "material white\n"
            "Kd 0.5 0.5 0.5\n"
            "\n"
            "material lamp\n"
            "Ke 10 10 10\n"},
      {"s.mtl", "newmtl white\n"
            "Kd 0.5 grey 0.5\n"
            "newmtl lamp\n"
            "Kd 0 0 0\n"}},
     "s.obj",
     {},
     "s.mtl:2:8: error: 'grey' is not a number: 'Kd' expects 3 numbers (r g b)"},
    {"obj_bad_index",
     {{"s.json", "{\n"
            "\"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 40, \"resolution\": [8, 8]},\n"
            "\"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5}},\n"
            "\"shapes\": [\n"
            "{\"type\": \"obj\", \"file\": \"m.obj\", \"material\": \"m\"},\n"
            "{\"type\": \"sphere\", \"radius\": 0.5, \"emission\": [1, 1, 1], \"transform\": {\"translate\": [0, 0, 3]}}\n"
            "]\n"
            "}\n"},
      {"m.obj", "@data:meshes/bad_index.obj"}},
     "s.json",
     {},
     "m.obj:15:7: error: at /shapes/0: vertex index 17 out of range (mesh has 12 vertices)"},
    {"obj_nonfinite",
     {{"s.json", "{\n"
            "\"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 40, \"resolution\": [8, 8]},\n"
            "\"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5}},\n"
            "\"shapes\": [\n"
            "{\"type\": \"obj\", \"file\": \"m.obj\", \"material\": \"m\"},\n"
            "{\"type\": \"sphere\", \"radius\": 0.5, \"emission\": [1, 1, 1], \"transform\": {\"translate\": [0, 0, 3]}}\n"
            "]\n"
            "}\n"},
      {"m.obj", "@data:meshes/nonfinite.obj"}},
     "s.json",
     {},
     "m.obj:3:5: error: at /shapes/0: non-finite vertex position at vertex 3"},
    {"obj_no_faces",
     {{"s.json", "{\n"
            "\"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 40, \"resolution\": [8, 8]},\n"
            "\"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5}},\n"
            "\"shapes\": [\n"
            "{\"type\": \"obj\", \"file\": \"m.obj\", \"material\": \"m\"},\n"
            "{\"type\": \"sphere\", \"radius\": 0.5, \"emission\": [1, 1, 1], \"transform\": {\"translate\": [0, 0, 3]}}\n"
            "]\n"
            "}\n"},
      {"m.obj", "@data:meshes/no_faces.obj"}},
     "s.json",
     {},
     "m.obj: error: at /shapes/0: OBJ file has no triangles (expected faces: 'f' lines)"},
    {"obj_all_degenerate",
     {{"s.json", "{\n"
            "\"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 40, \"resolution\": [8, 8]},\n"
            "\"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5}},\n"
            "\"shapes\": [\n"
            "{\"type\": \"obj\", \"file\": \"m.obj\", \"material\": \"m\"},\n"
            "{\"type\": \"sphere\", \"radius\": 0.5, \"emission\": [1, 1, 1], \"transform\": {\"translate\": [0, 0, 3]}}\n"
            "]\n"
            "}\n"},
      {"m.obj", "@data:meshes/all_degenerate.obj"}},
     "s.json",
     {},
     "m.obj: error: at /shapes/0: OBJ file has no triangles with non-zero area (all 2 are degenerate)"},
    {"ply_bad_index",
     {{"s.json", "{\n"
            "\"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 40, \"resolution\": [8, 8]},\n"
            "\"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5}},\n"
            "\"shapes\": [\n"
            "{\"type\": \"ply\", \"file\": \"m.ply\", \"material\": \"m\"},\n"
            "{\"type\": \"sphere\", \"radius\": 0.5, \"emission\": [1, 1, 1], \"transform\": {\"translate\": [0, 0, 3]}}\n"
            "]\n"
            "}\n"},
      {"m.ply", "@data:meshes/bad_index.ply"}},
     "s.json",
     {},
     "m.ply:13:7: error: at /shapes/0: vertex index 17 out of range (mesh has 3 vertices)"},
    {"ply_garbage",
     {{"s.json", "{\n"
            "\"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 40, \"resolution\": [8, 8]},\n"
            "\"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5}},\n"
            "\"shapes\": [\n"
            "{\"type\": \"ply\", \"file\": \"m.ply\", \"material\": \"m\"},\n"
            "{\"type\": \"sphere\", \"radius\": 0.5, \"emission\": [1, 1, 1], \"transform\": {\"translate\": [0, 0, 3]}}\n"
            "]\n"
            "}\n"},
      {"m.ply", "@data:meshes/garbage.ply"}},
     "s.json",
     {},
     "m.ply:1: error: at /shapes/0: not a PLY file: the first line is 'this is not a ply fi' (expected 'ply')"},
    {"ply_huge_count",
     {{"s.json", "{\n"
            "\"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 40, \"resolution\": [8, 8]},\n"
            "\"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5}},\n"
            "\"shapes\": [\n"
            "{\"type\": \"ply\", \"file\": \"m.ply\", \"material\": \"m\"},\n"
            "{\"type\": \"sphere\", \"radius\": 0.5, \"emission\": [1, 1, 1], \"transform\": {\"translate\": [0, 0, 3]}}\n"
            "]\n"
            "}\n"},
      {"m.ply", "@data:meshes/huge_count.ply"}},
     "s.json",
     {},
     "m.ply:4: error: at /shapes/0: PLY header announces 4000000000 'vertex' elements (at least 12 bytes each), but the file has only 0 bytes after the head"},
    {"ply_truncated_binary",
     {{"s.json", "{\n"
            "\"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 40, \"resolution\": [8, 8]},\n"
            "\"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5}},\n"
            "\"shapes\": [\n"
            "{\"type\": \"ply\", \"file\": \"m.ply\", \"material\": \"m\"},\n"
            "{\"type\": \"sphere\", \"radius\": 0.5, \"emission\": [1, 1, 1], \"transform\": {\"translate\": [0, 0, 3]}}\n"
            "]\n"
            "}\n"},
      {"m.ply", "@data:meshes/truncated_binary.ply"}},
     "s.json",
     {},
     "m.ply: error: at /shapes/0: PLY list 'vertex_indices' of 'face' element 2 has 3 entries, more than the rest of the file holds (at byte offset"},
    {"serialized_bad_magic",
     {{"s.xml", "<scene version=\"3.0.0\">\n"
            "    <sensor type=\"perspective\">\n"
            "        <film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/></film>\n"
            "    </sensor>\n"
            "    <emitter type=\"constant\"/>\n"
            "    <shape type=\"serialized\"><string name=\"filename\" value=\"m.serialized\"/></shape>\n"
            "</scene>\n"},
      {"m.serialized", "PLY not a mesh"}},
     "s.xml",
     {},
     "s.xml:6:30: error: <shape type=\"serialized\">: m.serialized: error: at <shape type=\"serialized\">: invalid .serialized file: not a Mitsuba .serialized file (the first two bytes are 0x4c50, expected the identifier 0x41c)"},
    {"serialized_truncated",
     {{"s.xml", "<scene version=\"3.0.0\">\n"
            "    <sensor type=\"perspective\">\n"
            "        <film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/></film>\n"
            "    </sensor>\n"
            "    <emitter type=\"constant\"/>\n"
            "    <shape type=\"serialized\"><string name=\"filename\" value=\"m.serialized\"/></shape>\n"
            "</scene>\n"},
      {"m.serialized", "@prefix:30:tests/data/mitsuba/meshes/quads.serialized"}},
     "s.xml",
     {},
     "s.xml:6:30: error: <shape type=\"serialized\">: m.serialized: error: at <shape type=\"serialized\">: invalid .serialized file: shape 0: the file ends inside the compressed data, in the texture coordinates (truncated file)"},
    {"serialized_shape_index_out_of_range",
     {{"s.xml", "<scene version=\"3.0.0\">\n"
            "    <sensor type=\"perspective\">\n"
            "        <film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/></film>\n"
            "    </sensor>\n"
            "    <emitter type=\"constant\"/>\n"
            "    <shape type=\"serialized\"><string name=\"filename\" value=\"m.serialized\"/><integer name=\"shape_index\" value=\"2\"/></shape>\n"
            "</scene>\n"},
      {"m.serialized", "@data:mitsuba/meshes/quads.serialized"}},
     "s.xml",
     {},
     "s.xml:6:30: error: <shape type=\"serialized\">: m.serialized: error: at <shape type=\"serialized\">: invalid .serialized file: shape_index 2 is out of range: the file holds 2 shapes (0..1)"},
    {"jpeg_not_jpeg",
     {{"s.xml", "<scene version=\"3.0.0\">\n"
            "    <sensor type=\"perspective\">\n"
            "        <film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/></film>\n"
            "    </sensor>\n"
            "    <emitter type=\"constant\"/>\n"
            "    <shape type=\"cube\"><bsdf type=\"diffuse\"><texture type=\"bitmap\" name=\"reflectance\"><string name=\"filename\" value=\"t.jpg\"/></texture></bsdf></shape>\n"
            "</scene>\n"},
      {"t.jpg", "nope"}},
     "s.xml",
     {},
     "s.xml:6:87: error: <texture type=\"bitmap\">: t.jpg: error: not a JPEG file (missing the start-of-image marker FF D8 FF)"},
    {"jpeg_truncated",
     {{"s.xml", "<scene version=\"3.0.0\">\n"
            "    <sensor type=\"perspective\">\n"
            "        <film type=\"hdrfilm\"><integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/></film>\n"
            "    </sensor>\n"
            "    <emitter type=\"constant\"/>\n"
            "    <shape type=\"cube\"><bsdf type=\"diffuse\"><texture type=\"bitmap\" name=\"reflectance\"><string name=\"filename\" value=\"t.jpg\"/></texture></bsdf></shape>\n"
            "</scene>\n"},
      {"t.jpg", "@prefix:400:tests/data/mitsuba/textures/stripes.jpg"}},
     "s.xml",
     {},
     "s.xml:6:87: error: <texture type=\"bitmap\">: t.jpg: error: corrupt or unsupported JPEG image (libjpeg: Premature end of JPEG file)"},
    {"png_bad_signature",
     {{"s.json", "{\n"
            "\"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 40, \"resolution\": [8, 8]},\n"
            "\"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": {\"type\": \"bitmap\", \"file\": \"t.png\"}}},\n"
            "\"shapes\": [\n"
            "{\"type\": \"cube\", \"material\": \"m\"},\n"
            "{\"type\": \"sphere\", \"radius\": 0.5, \"emission\": [1, 1, 1], \"transform\": {\"translate\": [0, 0, 3]}}\n"
            "]\n"
            "}\n"},
      {"t.png", "not a png at all"}},
     "s.json",
     {},
     "s.json:3:82: error: at /materials/m/reflectance/file: cannot read bitmap 't.png': not a PNG file (bad signature)"},
    {"png_truncated",
     {{"s.json", "{\n"
            "\"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 40, \"resolution\": [8, 8]},\n"
            "\"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": {\"type\": \"bitmap\", \"file\": \"t.png\"}}},\n"
            "\"shapes\": [\n"
            "{\"type\": \"cube\", \"material\": \"m\"},\n"
            "{\"type\": \"sphere\", \"radius\": 0.5, \"emission\": [1, 1, 1], \"transform\": {\"translate\": [0, 0, 3]}}\n"
            "]\n"
            "}\n"},
      {"t.png", "@prefix:60:tests/data/mitsuba/textures/tiles.png"}},
     "s.json",
     {},
     "s.json:3:82: error: at /materials/m/reflectance/file: cannot read bitmap 't.png': corrupt PNG image: chunk 'gAMA' at byte 46 announces 4 bytes, more than the 2 bytes left in the file (truncated or corrupt file?)"},
    {"exr_bad_magic",
     {{"s.json", "{\n"
            "\"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 40, \"resolution\": [8, 8]},\n"
            "\"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": {\"type\": \"bitmap\", \"file\": \"t.exr\"}}},\n"
            "\"shapes\": [\n"
            "{\"type\": \"cube\", \"material\": \"m\"},\n"
            "{\"type\": \"sphere\", \"radius\": 0.5, \"emission\": [1, 1, 1], \"transform\": {\"translate\": [0, 0, 3]}}\n"
            "]\n"
            "}\n"},
      {"t.exr", std::string("v/1\000garbage", 11)}},
     "s.json",
     {},
     "s.json:3:82: error: at /materials/m/reflectance/file: cannot read bitmap 't.exr': cannot read OpenEXR image: Cannot read image file \"t.exr\". File is n"},
    {"exr_truncated",
     {{"s.json", "{\n"
            "\"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 40, \"resolution\": [8, 8]},\n"
            "\"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": {\"type\": \"bitmap\", \"file\": \"t.exr\"}}},\n"
            "\"shapes\": [\n"
            "{\"type\": \"cube\", \"material\": \"m\"},\n"
            "{\"type\": \"sphere\", \"radius\": 0.5, \"emission\": [1, 1, 1], \"transform\": {\"translate\": [0, 0, 3]}}\n"
            "]\n"
            "}\n"},
      {"t.exr", "@prefix:400:scenes/textures/sky.exr"}},
     "s.json",
     {},
     "s.json:3:82: error: at /materials/m/reflectance/file: cannot read bitmap 't.exr': corrupt OpenEXR image: header attribute 'screenWindowCenter' announces 8 bytes, more than the 5 bytes left in the file (truncated or corrupt file?)"},
    {"cli_unsupported_extension",
     {{"s.txt", "hello"}},
     "s.txt",
     {},
     "s.txt: error: unsupported scene file extension '.txt' (supported: .json, .xml, .obj)"},
    {"cli_define_for_json",
     {{"s.json", "{\n"
            "\"camera\": {\"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov\": 40, \"resolution\": [8, 8]},\n"
            "\"materials\": {\"m\": {\"type\": \"diffuse\", \"reflectance\": 0.5}},\n"
            "\"shapes\": [\n"
            "{\"type\": \"cube\", \"material\": \"m\"},\n"
            "{\"type\": \"sphere\", \"radius\": 0.5, \"emission\": [1, 1, 1], \"transform\": {\"translate\": [0, 0, 3]}}\n"
            "]\n"
            "}\n"}},
     "s.json",
     {"-D", "x=1"},
     "s.json: error: scene parameters (-D x=...) apply only to Mitsuba .xml scenes"},
};
// clang-format on

std::string readFile(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

std::string contents(const std::string& spec) {
    const fs::path root = fs::path(UNIBEAM_SOURCE_DIR);
    if (spec.rfind("@data:", 0) == 0)
        return readFile(fs::path(UNIBEAM_TEST_DATA_DIR) / spec.substr(6));
    if (spec.rfind("@prefix:", 0) == 0) {
        const size_t colon = spec.find(':', 8);
        const size_t n = std::stoul(spec.substr(8, colon - 8));
        const std::string all = readFile(root / spec.substr(colon + 1));
        EXPECT_GT(all.size(), n) << spec;
        return all.substr(0, n);
    }
    return spec;
}

std::string replaceAll(std::string s, const std::string& from, const std::string& to) {
    for (size_t i = s.find(from); i != std::string::npos; i = s.find(from, i + to.size()))
        s.replace(i, from.size(), to);
    return s;
}

}  // namespace

TEST(MalformedInputs, EveryCaseExitsTwoNamingFileLocationAndExpectation) {
    ASSERT_GE(kCases.size(), 40u);
    std::set<std::string> names;
    for (const Case& c : kCases) {
        SCOPED_TRACE(c.name);
        EXPECT_TRUE(names.insert(c.name).second) << "duplicate case name";
        const fs::path dir =
            fs::temp_directory_path() /
            ("unibeam_malformed_" + std::string(c.name) + "_" + std::to_string(::getpid()));
        fs::remove_all(dir);
        fs::create_directories(dir);
        for (const auto& [file, spec] : c.files) {
            std::ofstream out(dir / file, std::ios::binary);
            out << contents(spec);
        }
        std::string cmd =
            std::string("'") + UNIBEAM_BINARY + "' info '" + (dir / c.main).string() + "'";
        for (const std::string& a : c.args) cmd += " '" + a + "'";
        const fs::path err = dir / "stderr.txt";
        cmd += " >/dev/null 2>'" + err.string() + "' </dev/null";
        const int status = std::system(cmd.c_str());
        ASSERT_TRUE(WIFEXITED(status)) << cmd;
        EXPECT_EQ(WEXITSTATUS(status), 2) << readFile(err);
        const std::string text = replaceAll(readFile(err), dir.string() + "/", "");
        const std::string first = text.substr(0, text.find('\n'));
        EXPECT_EQ(first.substr(0, c.firstDiagnostic.size()), c.firstDiagnostic) << text;
        fs::remove_all(dir);
    }
}
