#include "render/gl_api.hpp"

namespace stepwise::render {

std::string GlApi::load(GetProcAddress getProc) {
    // Casting void* to a function pointer is conditionally supported; every
    // platform with GL supports it (dlsym relies on the same).
#define STEPWISE_GL_LOAD(type, name)                                         \
    name = reinterpret_cast<type>(getProc("gl" #name));                      \
    if (!name) return "gl" #name;
    STEPWISE_GL_FUNCTIONS(STEPWISE_GL_LOAD)
#undef STEPWISE_GL_LOAD
    return "";
}

} // namespace stepwise::render
