#include "run/runner.hpp"

#include "run/session.hpp"

namespace haet {

RunStatus runScenario(const Scenario& sc, const RunOptions& opt, std::ostream& log) {
    std::unique_ptr<RunSession> run = RunSession::open(sc, opt, log);
    run->advance(sc.duration);
    return run->finish();
}

}  // namespace haet
