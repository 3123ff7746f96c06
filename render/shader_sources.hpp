#pragma once
/// \file shader_sources.hpp
/// GLSL sources from shaders/, embedded at build time.

#include <string_view>
#include <vector>

namespace stepwise::render {

struct ShaderSource {
    std::string_view name;  ///< file name in shaders/, e.g. "disc.frag"
    std::string_view text;
};

/// Every shader file, in the order CMake lists them.
const std::vector<ShaderSource>& shaderSources();

} // namespace stepwise::render
