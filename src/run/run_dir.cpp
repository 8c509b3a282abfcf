#include "run/run_dir.hpp"

#include <regex>
#include <system_error>
#include <vector>

#include "io/atomic_file.hpp"

namespace haet {

bool isRunOutputName(const std::string& name) {
    // The outputs of runner.cpp, and the temporary files of their atomic writes (io/atomic_file.hpp).
    static const std::regex re(
        R"((run\.json|series\.csv|final\.png|final\.csv|final\.data|(particles|walls|zones|polygons)\.pvd|)"
        R"((particles|polygons)_[0-9]{6,}\.vtu|walls_[0-9]{6,}\.vtp|zones_[0-9]{6,}\.vti|checkpoint_[0-9]{6,}\.haet|)"
        // run/measures.hpp: the fields of [[fields]] blocks (names: letters, digits, '_', '-'), the contact network
        R"(contacts\.pvd|contacts_[0-9]{6,}\.(vtp|csv)|fields_[A-Za-z0-9_-]+(\.pvd|\.csv|_[0-9]{6,}\.vti)))"
        R"((\.tmp\.[0-9]+)?)");
    return std::regex_match(name, re);
}

void prepareRunDirectory(const std::filesystem::path& dir) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw IoError(dir, "cannot create the output directory: " + ec.message());
    if (!std::filesystem::is_directory(dir, ec)) throw IoError(dir, "the output path is not a directory");
    // run.json first: a run stopped while clearing leaves no "completed" from the run before.
    std::filesystem::remove(dir / "run.json", ec);
    if (ec) throw IoError(dir / "run.json", "cannot remove the previous run's file: " + ec.message());
    std::vector<std::filesystem::path> old;  // listed first: removing while iterating is unspecified
    for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
        if (isRunOutputName(it->path().filename().string()) && it->is_regular_file(ec)) old.push_back(it->path());
    if (ec) throw IoError(dir, "cannot read the output directory: " + ec.message());
    for (const std::filesystem::path& p : old)
        if (!std::filesystem::remove(p, ec) && ec)
            throw IoError(p, "cannot remove the previous run's file: " + ec.message());
}

}  // namespace haet
