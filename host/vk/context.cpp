#include "host/vk/context.h"

#include "host/vk/check.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

namespace spw::vk {
namespace {

constexpr uint32_t kApiVersion = VK_API_VERSION_1_2;
constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

std::atomic<std::uint64_t> gValidationMessages{0};

std::string versionString(uint32_t v) {
    return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) +
           "." + std::to_string(VK_API_VERSION_PATCH(v));
}

const char* typeName(VkPhysicalDeviceType t) {
    switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
        return "discrete gpu";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
        return "integrated gpu";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
        return "virtual gpu";
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
        return "cpu";
    default:
        return "other";
    }
}

// Warnings and errors from the validation layer: printed and counted. The loader's own chatter
// (about drivers it skipped) is not the layer's and is left out.
VKAPI_ATTR VkBool32 VKAPI_CALL onDebugMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                              VkDebugUtilsMessageTypeFlagsEXT,
                                              const VkDebugUtilsMessengerCallbackDataEXT* data,
                                              void* user) {
    if (data && data->pMessageIdName && std::strcmp(data->pMessageIdName, "Loader Message") == 0)
        return VK_FALSE;
    ++gValidationMessages;
    if (user) ++*static_cast<std::atomic<std::uint64_t>*>(user);
    std::fprintf(stderr, "spillway: vulkan validation %s: %s\n",
                 severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "error" : "warning",
                 data && data->pMessage ? data->pMessage : "(no message)");
    return VK_FALSE;
}

VkDebugUtilsMessengerCreateInfoEXT messengerInfo(std::atomic<std::uint64_t>* counter) {
    auto info = zeroed<VkDebugUtilsMessengerCreateInfoEXT>(
        VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT);
    info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                           VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    info.pfnUserCallback = onDebugMessage;
    info.pUserData = counter;
    return info;
}

bool validationRequested(const VulkanConfig& config) {
    const char* env = std::getenv("SPILLWAY_VK_VALIDATION");
    return config.validation || (env && *env && std::strcmp(env, "0") != 0);
}

// Creates the instance, or throws NoDeviceError when the loader finds no driver.
// The driver manifests the loader is told to read (VK_DRIVER_FILES, or VK_ICD_FILENAMES, the
// older name it replaces) that it cannot use, as "VK_ICD_FILENAMES names '/a.json', which does
// not exist" ("" where each is a folder or a file that reads as a manifest: JSON whose ICD
// object has a library_path); `usable` is whether any other entry is left. The loader itself
// reports a truncated manifest as VK_ERROR_OUT_OF_HOST_MEMORY, and a missing one not at all.
std::string unusableDriverFiles(bool& usable) {
    usable = true;
    const char* var = "VK_DRIVER_FILES";
    const char* value = std::getenv(var);
    if (!value || !*value) var = "VK_ICD_FILENAMES", value = std::getenv(var);
    if (!value || !*value) return "";
    std::string bad;
    int good = 0;
    std::stringstream entries(value);
    for (std::string entry; std::getline(entries, entry, ':');) {
        if (entry.empty()) continue;
        std::error_code ec;
        std::string why;
        if (!std::filesystem::exists(entry, ec)) {
            why = "which does not exist";
        } else if (!std::filesystem::is_directory(entry, ec)) {
            std::ifstream in(entry);
            const nlohmann::json m = nlohmann::json::parse(in, nullptr, false);
            if (m.is_discarded() || !m.is_object() || !m.contains("ICD") || !m["ICD"].is_object() ||
                !m["ICD"].contains("library_path") || !m["ICD"]["library_path"].is_string())
                why = "which is not a Vulkan driver manifest (JSON whose ICD object names a "
                      "library_path)";
        }
        if (why.empty()) {
            ++good;
            continue;
        }
        bad += (bad.empty() ? std::string(var) + " names '" : ", '") + entry + "', " + why;
    }
    usable = good > 0;
    return bad;
}

VkInstance createInstance(bool validation, std::atomic<std::uint64_t>* counter) {
    bool usable = true;
    const std::string unusable = unusableDriverFiles(usable);
    if (!usable) throw NoDeviceError(unusable);
    uint32_t loaderVersion = VK_API_VERSION_1_0;
    if (vkEnumerateInstanceVersion(&loaderVersion) != VK_SUCCESS || loaderVersion < kApiVersion)
        throw NoDeviceError("the Vulkan loader supports only Vulkan " +
                            versionString(loaderVersion) + "; 1.2 is needed");
    std::vector<const char*> layers, extensions;
    VkDebugUtilsMessengerCreateInfoEXT debug = messengerInfo(counter);
    if (validation) {
        uint32_t n = 0;
        SPW_VK_CHECK(vkEnumerateInstanceLayerProperties(&n, nullptr));
        std::vector<VkLayerProperties> available(n);
        SPW_VK_CHECK(vkEnumerateInstanceLayerProperties(&n, available.data()));
        bool found =
            std::any_of(available.begin(), available.end(), [](const VkLayerProperties& l) {
                return std::strcmp(l.layerName, kValidationLayer) == 0;
            });
        if (!found)
            throw std::runtime_error(std::string("Vulkan validation was requested but ") +
                                     kValidationLayer +
                                     " is not installed (Debian package vulkan-validationlayers)");
        layers.push_back(kValidationLayer);
        extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
        extensions.push_back(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
    }
    // Beyond the core checks: synchronization validation (the barriers between host writes,
    // copies, dispatches and host reads).
    const VkValidationFeatureEnableEXT enables[] = {
        VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
    auto features = zeroed<VkValidationFeaturesEXT>(VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT);
    features.enabledValidationFeatureCount = 1;
    features.pEnabledValidationFeatures = enables;
    debug.pNext = &features;
    auto app = zeroed<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
    app.pApplicationName = "spillway";
    app.pEngineName = "spillway";
    app.apiVersion = kApiVersion;
    auto info = zeroed<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
    info.pNext = validation ? &debug : nullptr; // also catches messages of instance creation
    info.pApplicationInfo = &app;
    info.enabledLayerCount = uint32_t(layers.size());
    info.ppEnabledLayerNames = layers.data();
    info.enabledExtensionCount = uint32_t(extensions.size());
    info.ppEnabledExtensionNames = extensions.data();
    VkInstance instance = VK_NULL_HANDLE;
    VkResult r = vkCreateInstance(&info, nullptr, &instance);
    if (r == VK_ERROR_INCOMPATIBLE_DRIVER || r == VK_ERROR_INITIALIZATION_FAILED) {
        const char* files = std::getenv("VK_DRIVER_FILES");
        throw NoDeviceError(std::string("no Vulkan driver found (vkCreateInstance returned ") +
                            resultName(r) +
                            (files ? std::string("; VK_DRIVER_FILES=") + files : std::string()) +
                            ")" + (unusable.empty() ? "" : "; " + unusable));
    }
    if (r != VK_SUCCESS && !unusable.empty())
        throw NoDeviceError(std::string("vkCreateInstance returned ") + resultName(r) + "; " +
                            unusable);
    SPW_VK_CHECK(r);
    return instance;
}

struct InstanceOwner {
    VkInstance instance;
    ~InstanceOwner() {
        if (instance) vkDestroyInstance(instance, nullptr);
    }
};

std::vector<VkPhysicalDevice> physicalDevices(VkInstance instance) {
    uint32_t n = 0;
    VkResult r = vkEnumeratePhysicalDevices(instance, &n, nullptr);
    if (r == VK_ERROR_INITIALIZATION_FAILED) return {};
    SPW_VK_CHECK(r);
    std::vector<VkPhysicalDevice> devices(n);
    if (n) SPW_VK_CHECK(vkEnumeratePhysicalDevices(instance, &n, devices.data()));
    devices.resize(n);
    return devices;
}

// The queue family Spillway computes on: a compute-only one where the device has it (it runs
// beside graphics work), else any with compute. UINT32_MAX when there is none.
uint32_t computeFamily(VkPhysicalDevice device) {
    uint32_t n = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(device, &n, nullptr);
    std::vector<VkQueueFamilyProperties> families(n);
    vkGetPhysicalDeviceQueueFamilyProperties(device, &n, families.data());
    uint32_t any = UINT32_MAX;
    for (uint32_t i = 0; i < n; ++i) {
        if (!(families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) || families[i].queueCount == 0)
            continue;
        if (!(families[i].queueFlags & VK_QUEUE_GRAPHICS_BIT)) return i;
        if (any == UINT32_MAX) any = i;
    }
    return any;
}

DeviceInfo describe(VkPhysicalDevice device, uint32_t index) {
    DeviceInfo d;
    d.index = index;
    VkPhysicalDeviceProperties props{};
    vkGetPhysicalDeviceProperties(device, &props);
    d.name = props.deviceName;
    d.type = typeName(props.deviceType);
    d.api = versionString(props.apiVersion);
    if (props.apiVersion < kApiVersion) {
        d.whyNot = "Vulkan " + d.api + " (1.2 needed)";
        d.driver = "driver version " + std::to_string(props.driverVersion);
        return d;
    }
    auto driver = zeroed<VkPhysicalDeviceDriverProperties>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES);
    auto props2 =
        zeroed<VkPhysicalDeviceProperties2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2);
    props2.pNext = &driver;
    vkGetPhysicalDeviceProperties2(device, &props2);
    d.driver = std::string(driver.driverName) + ": " + driver.driverInfo;
    auto f12 = zeroed<VkPhysicalDeviceVulkan12Features>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES);
    auto features = zeroed<VkPhysicalDeviceFeatures2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2);
    features.pNext = &f12;
    vkGetPhysicalDeviceFeatures2(device, &features);
    if (computeFamily(device) == UINT32_MAX)
        d.whyNot = "no compute queue";
    else if (!f12.scalarBlockLayout)
        d.whyNot = "no scalarBlockLayout (the kernels' buffer layout)";
    d.usable = d.whyNot.empty();
    return d;
}

std::string lower(std::string s) {
    for (char& c : s)
        c = char(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

std::string listing(const std::vector<DeviceInfo>& infos) {
    std::string s;
    for (const DeviceInfo& d : infos)
        s += "\n  " + std::to_string(d.index) + ": " + d.name +
             (d.usable ? "" : " (unusable: " + d.whyNot + ")");
    return s;
}

// The device `--device` names (an index, or part of a name, any case), or the first usable one
// where it names none; throws where there is no such device or it is not usable.
size_t chooseDevice(const std::string& device, const std::vector<DeviceInfo>& infos) {
    if (device.empty()) {
        for (const DeviceInfo& d : infos)
            if (d.usable) return d.index;
        throw NoDeviceError("no usable Vulkan device:" + listing(infos));
    }
    const bool numeric = std::all_of(device.begin(), device.end(), [](char c) {
        return std::isdigit(static_cast<unsigned char>(c));
    });
    for (const DeviceInfo& d : infos) {
        const bool match = numeric ? std::to_string(d.index) == device
                                   : lower(d.name).find(lower(device)) != std::string::npos;
        if (!match) continue;
        if (!d.usable)
            throw std::runtime_error("--device " + device + ": " + d.name +
                                     " is not usable: " + d.whyNot);
        return d.index;
    }
    throw std::runtime_error("--device " + device +
                             ": no such Vulkan device; there are:" + listing(infos));
}

} // namespace

std::uint64_t validationMessageCount() {
    return gValidationMessages.load();
}

std::vector<DeviceInfo> listDevices() {
    InstanceOwner owner{createInstance(false, nullptr)};
    std::vector<DeviceInfo> out;
    std::vector<VkPhysicalDevice> devices = physicalDevices(owner.instance);
    for (uint32_t i = 0; i < devices.size(); ++i)
        out.push_back(describe(devices[i], i));
    return out;
}

AutoChoice chooseAutoDevice(const std::vector<DeviceInfo>& devices, bool softwareAllowed) {
    for (const char* type : {"discrete gpu", "integrated gpu"})
        for (const DeviceInfo& d : devices)
            if (d.usable && d.type == type)
                return {int(d.index), "device " + std::to_string(d.index) + " (" + d.name +
                                          "), the first usable " + type};
    if (softwareAllowed)
        for (const DeviceInfo& d : devices)
            if (d.usable)
                return {int(d.index), "device " + std::to_string(d.index) + " (" + d.name +
                                          "): no GPU, but the Vulkan driver variables ask for "
                                          "this driver"};
    return {-1, "cpu: no usable GPU (a software device such as lavapipe shades more slowly "
                "than the cpu backend on the same cores; --backend vulkan takes it)"};
}

bool driverVariablesSet() {
    for (const char* v : {"VK_DRIVER_FILES", "VK_ICD_FILENAMES", "VK_ADD_DRIVER_FILES"})
        if (const char* value = std::getenv(v); value && *value) return true;
    return false;
}

std::vector<std::string> gpuDeviceFiles(const std::string& root) {
    const auto starts = [](const std::string& name, const char* prefix) {
        return name.rfind(prefix, 0) == 0;
    };
    std::vector<std::string> found;
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(root + "/dri", ec)) {
        const std::string name = entry.path().filename().string();
        if (starts(name, "renderD") || starts(name, "card")) found.push_back(entry.path().string());
    }
    for (const auto& entry : std::filesystem::directory_iterator(root, ec)) {
        const std::string name = entry.path().filename().string();
        const bool nvidia =
            starts(name, "nvidia") && name.size() > 6 &&
            (std::isdigit(static_cast<unsigned char>(name[6])) || name == "nvidiactl");
        if (nvidia || name == "dxg" || name == "kgsl-3d0" || starts(name, "mali"))
            found.push_back(entry.path().string());
    }
    std::sort(found.begin(), found.end());
    return found;
}

std::optional<AutoChoice> autoChoiceWithoutLoader() {
    if (driverVariablesSet() || !gpuDeviceFiles().empty()) return std::nullopt;
    return AutoChoice{-1,
                      "cpu: no GPU on this machine (no device file in /dev/dri, no /dev/nvidia*, "
                      "/dev/dxg or another GPU's), so no Vulkan driver can reach one; a "
                      "software device such as lavapipe shades more slowly than the cpu "
                      "backend on the same cores; --backend vulkan takes it"};
}

Context::Context(const VulkanConfig& config) {
    validation_ = validationRequested(config);
    instance_ = createInstance(validation_, &messages_);
    try {
        if (validation_) {
            auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
                vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
            if (!create)
                throw std::runtime_error(
                    "vkCreateDebugUtilsMessengerEXT is missing although validation is on");
            VkDebugUtilsMessengerCreateInfoEXT info = messengerInfo(&messages_);
            SPW_VK_CHECK(create(instance_, &info, nullptr, &messenger_));
        }

        std::vector<VkPhysicalDevice> devices = physicalDevices(instance_);
        std::vector<DeviceInfo> infos;
        for (uint32_t i = 0; i < devices.size(); ++i)
            infos.push_back(describe(devices[i], i));
        if (devices.empty())
            throw NoDeviceError("no Vulkan device found (the loader sees drivers but no device)");

        const size_t chosen = chooseDevice(config.device, infos);
        physical_ = devices[chosen];
        info_ = infos[chosen];
        info_.usable = true;
        vkGetPhysicalDeviceProperties(physical_, &properties_);
        vkGetPhysicalDeviceMemoryProperties(physical_, &memory_);
        queueFamily_ = computeFamily(physical_);

        uint32_t n = 0;
        vkGetPhysicalDeviceQueueFamilyProperties(physical_, &n, nullptr);
        std::vector<VkQueueFamilyProperties> families(n);
        vkGetPhysicalDeviceQueueFamilyProperties(physical_, &n, families.data());
        if (families[queueFamily_].timestampValidBits > 0 &&
            properties_.limits.timestampPeriod > 0.0f)
            timestampPeriodNs_ = double(properties_.limits.timestampPeriod);

        const float priority = 1.0f;
        auto queue = zeroed<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
        queue.queueFamilyIndex = queueFamily_;
        queue.queueCount = 1;
        queue.pQueuePriorities = &priority;
        auto f12 = zeroed<VkPhysicalDeviceVulkan12Features>(
            VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES);
        f12.scalarBlockLayout = VK_TRUE;
        auto info = zeroed<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO);
        info.pNext = &f12;
        info.queueCreateInfoCount = 1;
        info.pQueueCreateInfos = &queue;
        SPW_VK_CHECK(vkCreateDevice(physical_, &info, nullptr, &device_));
        vkGetDeviceQueue(device_, queueFamily_, 0, &queue_);
    } catch (...) {
        release();
        throw;
    }
}

Context::~Context() {
    release();
}

void Context::release() {
    if (device_) {
        vkDeviceWaitIdle(device_);
        vkDestroyDevice(device_, nullptr);
        device_ = VK_NULL_HANDLE;
    }
    if (messenger_) {
        auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
        if (destroy) destroy(instance_, messenger_, nullptr);
        messenger_ = VK_NULL_HANDLE;
    }
    if (instance_) {
        vkDestroyInstance(instance_, nullptr);
        instance_ = VK_NULL_HANDLE;
    }
}

} // namespace spw::vk
