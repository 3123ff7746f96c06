# Build step: turns the GLSL files in shaders/ into a C++ table so the binary
# needs no source tree at run time (a fresh clone or an installed binary
# works the same). Run as: cmake -DOUT=file.cpp -DSHADER_DIR=dir
# "-DSHADERS=a.vert;b.frag" -P embed_shaders.cmake
set(text "// Generated from shaders/ by render/embed_shaders.cmake. Do not edit.\n")
string(APPEND text "#include \"shader_sources.hpp\"\n\nnamespace stepwise::render {\n\n")
string(APPEND text "const std::vector<ShaderSource>& shaderSources() {\n    static const std::vector<ShaderSource> sources = {\n")
foreach(name IN LISTS SHADERS)
  file(READ "${SHADER_DIR}/${name}" body)
  string(APPEND text "        {\"${name}\", R\"glsl(${body})glsl\"},\n")
endforeach()
string(APPEND text "    };\n    return sources;\n}\n\n} // namespace stepwise::render\n")
# Only touch the output when it changes, so unchanged shaders rebuild nothing.
if(EXISTS "${OUT}")
  file(READ "${OUT}" old)
endif()
if(NOT "${old}" STREQUAL "${text}")
  file(WRITE "${OUT}" "${text}")
endif()
