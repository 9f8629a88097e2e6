#include "host/app/devices_command.h"

#include "host/app/usage_error.h"
#include "host/vk/context.h"

#include <cstdio>

namespace spw {

int devicesCommand(const std::vector<std::string>& args) {
    if (!args.empty()) throw UsageError("devices takes no arguments");
    std::vector<vk::DeviceInfo> devices;
    try {
        devices = vk::listDevices();
    } catch (const vk::NoDeviceError& e) {
        std::fprintf(stderr, "spillway: no Vulkan device: %s\n", e.what());
        std::printf("--backend auto takes cpu: no Vulkan device (%s)\n", e.what());
        return 1;
    }
    if (devices.empty()) {
        std::fprintf(stderr,
                     "spillway: no Vulkan device (the loader found drivers but no device)\n");
        std::printf("--backend auto takes cpu: no Vulkan device (the drivers offer none)\n");
        return 1;
    }
    for (const vk::DeviceInfo& d : devices)
        std::printf("%u: %s\n   type: %s, Vulkan %s, driver: %s\n   %s\n", d.index, d.name.c_str(),
                    d.type.c_str(), d.api.c_str(), d.driver.c_str(),
                    d.usable ? "usable" : ("unusable: " + d.whyNot).c_str());
    const std::optional<vk::AutoChoice> known = vk::autoChoiceWithoutLoader();
    std::printf(
        "--backend auto takes %s\n",
        (known ? *known : vk::chooseAutoDevice(devices, vk::driverVariablesSet())).why.c_str());
    return 0;
}

} // namespace spw
