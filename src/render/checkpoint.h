// Checkpoints of a progressive render: everything needed to continue it so that the
// final image equals an uninterrupted render with the same seed bit for bit.
//
// Every iteration's random numbers and radii are functions of (seed, iteration index)
// alone (Rng::forPath, VertexCM::radiusAt), so the state is what the loop accumulated:
// the film's double-precision sums, each technique layer's sums, the Welford mean and
// M2 of --variance, the iteration count, the elapsed seconds and the rejected-
// contribution counts.
//
// File layout (little-endian, all sizes explicit):
//   "UBCKPT\n\0"                       8-byte magic
//   u32 format version (kCheckpointFormat)
//   str unibeam version, str scene digest (FNV-1a 64 of the scene file's bytes, hex),
//   str options (one "key=value" line per option that affects the image), u32 width,
//   u32 height, i32 iterations, f64 seconds,
//   u32 layer count, then per layer: str name, u64 rejected, f64[3 w h] sums;
//   u64 film rejected, f64[3 w h] film sums, u8 variance?, [f64[3 w h] mean, f64 m2],
//   u32 rejection count entries, then per entry: str name, u64 count
//   u64 FNV-1a 64 of all preceding bytes
// (str = u32 length + bytes). Written atomically: a temporary file in the same folder,
// fsync, rename over FILE, fsync of the folder. The old checkpoint stays until the new
// one is complete.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "render/contribution_guard.h"

namespace ub {

constexpr uint32_t kCheckpointFormat = 1;

struct CheckpointHeader {
    std::string version;      ///< unibeam version that wrote it
    std::string sceneDigest;  ///< digestFile(scene)
    std::string options;      ///< "key=value\n" lines
    uint32_t width = 0, height = 0;
};

struct ProgressiveState {
    int iterations = 0;
    double seconds = 0;
    std::vector<double> film;  ///< 3 per pixel: the sums of the iterations
    uint64_t filmRejected = 0;
    std::vector<std::string> layerNames;
    std::vector<std::vector<double>> layers;
    std::vector<uint64_t> layerRejected;
    bool hasVariance = false;
    std::vector<double> varianceMean, varianceM2;
    RejectionCounts rejected;  ///< the integrator's counts so far
};

/// FNV-1a 64 of a file's bytes as 16 hex digits. Throws InputError if it cannot be read.
std::string digestFile(const std::string& path);

/// Writes the checkpoint atomically. Throws std::runtime_error (naming the file and the
/// system error, e.g. "No space left on device") when it cannot; the previous file at
/// `path` is then untouched and no temporary file is left. failAfterBytesForTest >= 0
/// makes the write fail with ENOSPC after that many bytes (tests only).
void writeCheckpoint(const std::string& path, const CheckpointHeader& header,
                     const ProgressiveState& state, long long failAfterBytesForTest = -1);

/// Reads a checkpoint and checks it against `expected`: a truncated or corrupt file, another
/// format or unibeam version, another scene, other options (naming each differing one) or
/// another resolution throws InputError naming the file, exit status 2 in the CLI.
ProgressiveState readCheckpoint(const std::string& path, const CheckpointHeader& expected);

}  // namespace ub
