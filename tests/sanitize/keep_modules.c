/* Preloaded into the sanitized test run (scripts/test.sh): dlclose() keeps every module mapped.
 *
 * LeakSanitizer looks for pointers to each allocation in the globals of every library still
 * mapped at exit. The Vulkan loader closes the driver and the validation layer at
 * vkDestroyInstance, GLFW closes Mesa's OpenGL driver at glfwTerminate, and Open MPI closes its
 * components at MPI_Finalize; what their globals still pointed to is then reported as leaked,
 * from an "<unknown module>" that no suppression can name. With the modules kept, those blocks
 * stay reachable, and a real leak in any of them is reported with its library's name. Nothing
 * is unloaded for real in a process about to exit, so no behaviour under test changes. */
#include <dlfcn.h>

int dlclose(void* handle) {
    (void)handle;
    return 0;
}
