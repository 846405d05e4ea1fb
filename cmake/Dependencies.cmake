# Finds every dependency through find_package / pkg-config. A missing one
# stops configuration with the name of the Debian package that provides it.

macro(ub_require found_var what debian_pkg)
  if(NOT ${found_var})
    message(FATAL_ERROR "unibeam needs ${what}: install the Debian package '${debian_pkg}' "
                        "(apt-get install ${debian_pkg}), or run scripts/setup.sh")
  endif()
endmacro()

find_package(embree 3 CONFIG QUIET)
ub_require(embree_FOUND "Embree 3" libembree-dev)

find_package(TBB CONFIG QUIET)
ub_require(TBB_FOUND "oneTBB" libtbb-dev)

find_package(OpenEXR CONFIG QUIET)
ub_require(OpenEXR_FOUND "OpenEXR" libopenexr-dev)

find_package(PNG QUIET)
ub_require(PNG_FOUND "libpng" libpng-dev)

find_package(ZLIB QUIET)
ub_require(ZLIB_FOUND "zlib" zlib1g-dev)

find_package(JPEG QUIET)
ub_require(JPEG_FOUND "libjpeg (libjpeg-turbo)" libjpeg62-turbo-dev)
find_path(UB_STB_INCLUDE stb/stb_image.h)
ub_require(UB_STB_INCLUDE "stb_image (BMP, TGA, RGBE, PNM textures)" libstb-dev)

find_package(nlohmann_json 3 CONFIG QUIET)
ub_require(nlohmann_json_FOUND "nlohmann-json" nlohmann-json3-dev)

find_package(CLI11 CONFIG QUIET)
ub_require(CLI11_FOUND "CLI11" libcli11-dev)

find_package(tinyobjloader CONFIG QUIET)
ub_require(tinyobjloader_FOUND "tinyobjloader (OBJ meshes)" libtinyobjloader-dev)

find_package(pugixml CONFIG QUIET)
ub_require(pugixml_FOUND "pugixml (Mitsuba XML scenes)" libpugixml-dev)


find_package(OpenCL QUIET)
ub_require(OpenCL_FOUND "OpenCL ICD loader and headers" "ocl-icd-opencl-dev opencl-headers")
find_path(UB_CLHPP_INCLUDE CL/opencl.hpp)
ub_require(UB_CLHPP_INCLUDE "OpenCL C++ headers" opencl-clhpp-headers)

# OpenVDB ships its FindOpenVDB.cmake module in a Debian-specific folder.
list(APPEND CMAKE_MODULE_PATH /usr/lib/x86_64-linux-gnu/cmake/OpenVDB /usr/lib/cmake/OpenVDB)
find_package(OpenVDB QUIET)
ub_require(OpenVDB_FOUND "OpenVDB" "libopenvdb-dev libboost-iostreams-dev")
find_path(UB_NANOVDB_INCLUDE nanovdb/NanoVDB.h)
ub_require(UB_NANOVDB_INCLUDE "NanoVDB" libnanovdb-dev)

if(UNIBEAM_BUILD_TESTS)
  find_package(GTest CONFIG QUIET)
  if(NOT GTest_FOUND)
    find_package(GTest QUIET)
  endif()
  ub_require(GTest_FOUND "GoogleTest" "libgtest-dev libgmock-dev")
endif()
if(UNIBEAM_BUILD_BENCH)
  find_package(benchmark CONFIG QUIET)
  ub_require(benchmark_FOUND "Google Benchmark" libbenchmark-dev)
endif()
