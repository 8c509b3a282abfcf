#pragma once
// MPI for `haet run` started by mpirun (docs/parallel.md): initialised when the environment says that mpirun
// started the process and the build has MPI (CMake option HAET_MPI), finalised when the scope ends, on every exit
// path. Without either, one process, and nothing of MPI is touched.
#include <memory>

#include "tdm/ranks.hpp"

namespace haet {

class MpiScope {
public:
    MpiScope(int& argc, char**& argv);
    ~MpiScope();
    MpiScope(const MpiScope&) = delete;
    MpiScope& operator=(const MpiScope&) = delete;

    /// The ranks of this run when there are more than one; null in one process (mpirun -np 1 included).
    Ranks* ranks();
    int rank() const;
    /// Whether the ranks have started talking: after that, a failure on one rank leaves the others waiting in a
    /// collective, and the run must end on all of them at once (abort).
    bool talking() const;
    /// Ends every rank with this exit code (mpirun returns it).
    [[noreturn]] void abort(int code);

    struct Impl;

private:
    std::unique_ptr<Impl> impl_;
};

/// Whether this build can run across ranks (HAET_MPI).
bool mpiBuilt();

}  // namespace haet
