// The OpenCL sources embedded at build time (cmake/EmbedKernels.cmake).
#pragma once

#include <cstddef>

namespace ub {

struct EmbeddedKernelFile {
    const char* name;  ///< file name (kernels/NAME or kernels/shared/NAME)
    const char* text;
};
extern const EmbeddedKernelFile kEmbeddedKernelFiles[];
extern const size_t kEmbeddedKernelFileCount;

}  // namespace ub
