// Fuzz target: the STL reader (io/stl.hpp), ASCII and binary, from memory through the stream entry point the file
// reader uses. Bad input is a StlError; anything else escaping, a crash or a sanitizer report is a finding.
#include "io/stl.hpp"

#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    std::istringstream in(std::string(reinterpret_cast<const char*>(data), size), std::ios::binary);
    try {
        const haet::StlMesh mesh = haet::readStl(in, "fuzz.stl");
        if (mesh.triangles.empty()) __builtin_trap();  // the reader promises triangles or an error
    } catch (const haet::StlError&) {
    }
    return 0;
}
