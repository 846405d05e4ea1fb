// `unibeam devices`: the OpenCL platforms and devices the estimate pass can use.
#include <cstdio>

#include "app/commands.h"
#include "cl/cl_runtime.h"

namespace ub::app {

int runDevices() {
    std::string error;
    const std::vector<ClDeviceDescription> devices = listClDevices(&error);
    if (devices.empty()) {
        std::fprintf(stderr, "unibeam: error: %s\n", error.c_str());
        return 2;
    }
    for (const ClDeviceDescription& d : devices)
        std::printf(
            "%d:%d  %s  [%s, platform %s]\n      %s, driver %s, %u compute units, %.0f MiB "
            "global memory, %.0f MiB max allocation\n",
            d.platformIndex, d.deviceIndex, d.device.c_str(), d.type.c_str(), d.platform.c_str(),
            d.version.c_str(), d.driver.c_str(), d.computeUnits,
            double(d.globalMemBytes) / (1024.0 * 1024.0),
            double(d.maxAllocBytes) / (1024.0 * 1024.0));
    return 0;
}

}  // namespace ub::app
