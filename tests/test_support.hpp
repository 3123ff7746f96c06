#pragma once
/// \file test_support.hpp
/// Small helpers the test files share.

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace stepwise::test {

/// The whole file as bytes; empty when it cannot be read (tests compare
/// against expected contents, so a missing file fails there, visibly).
inline std::string readFile(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

} // namespace stepwise::test
