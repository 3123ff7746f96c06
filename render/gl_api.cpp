#include "gl_api.hpp"

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

namespace {
GLuint compileShader(const GlApi& gl, GLenum stage, const std::string& source, const std::string& label,
                     std::string& error) {
    const GLuint shader = gl.CreateShader(stage);
    const char* text = source.c_str();
    gl.ShaderSource(shader, 1, &text, nullptr);
    gl.CompileShader(shader);
    GLint ok = 0;
    gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (ok) return shader;
    char log[4096] = {};
    gl.GetShaderInfoLog(shader, sizeof log, nullptr, log);
    gl.DeleteShader(shader);
    error = "shader " + label + " does not compile:\n" + log;
    return 0;
}
} // namespace

GLuint linkProgram(const GlApi& gl, const std::string& vertexSource, const std::string& fragmentSource,
                   const std::string& label, std::string& error) {
    const GLuint vs = compileShader(gl, GL_VERTEX_SHADER, vertexSource, label + " (vertex)", error);
    if (!vs) return 0;
    const GLuint fs = compileShader(gl, GL_FRAGMENT_SHADER, fragmentSource, label + " (fragment)", error);
    if (!fs) {
        gl.DeleteShader(vs);
        return 0;
    }
    const GLuint program = gl.CreateProgram();
    gl.AttachShader(program, vs);
    gl.AttachShader(program, fs);
    gl.LinkProgram(program);
    gl.DeleteShader(vs);
    gl.DeleteShader(fs);
    GLint ok = 0;
    gl.GetProgramiv(program, GL_LINK_STATUS, &ok);
    if (ok) return program;
    char log[4096] = {};
    gl.GetProgramInfoLog(program, sizeof log, nullptr, log);
    gl.DeleteProgram(program);
    error = "program " + label + " does not link:\n" + log;
    return 0;
}

} // namespace stepwise::render
