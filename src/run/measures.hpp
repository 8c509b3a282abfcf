#pragma once
// What a run measures beyond its series and snapshots (docs/scenario.md, "Fields", "Regions", "Contacts";
// docs/physics.md L): the coarse-grained fields of its [[fields]] blocks (fields_NAME.pvd of fields_NAME_K.vti, and
// fields_NAME.csv for 1-axis grids), the stress tensor of the domain and of its [[regions]] in series.csv, and the
// contact network at the snapshots (contacts.pvd of contacts_K.vtp, contacts_K.csv). The numbers come from
// measure/field_grid.hpp; this is their schedule, their inputs (the particles, the force pass's contacts, the
// event-driven collisions) and their files.
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "edm/engine.hpp"
#include "io/checkpoint.hpp"
#include "measure/field_grid.hpp"
#include "scenario/definition.hpp"
#include "tdm/contact_record.hpp"
#include "world/world.hpp"

namespace haet {

template <int D>
class Measures {
public:
    /// snapshotPeriod: the run's (the fields' default period); < 0: none.
    Measures(const Scenario& sc, const World<D>& w, std::filesystem::path dir, double snapshotPeriod);
    ~Measures();

    /// series.csv's columns of the stress tensors (empty with [output] stress = false).
    std::vector<std::string> columns() const;
    /// Those columns' values now: kinetic and contact stress at this time (the contacts when valid), the collisions'
    /// stress since the last row (window: its length [s]).
    std::vector<std::optional<double>> row(const World<D>& w, bool contactsValid, double window);

    /// Whether anything reads the force pass's contacts: then the engine records them at the times asked for.
    bool wantsContacts() const { return wantContacts_; }
    ContactSink<D>* sink() { return &sink_; }
    /// The next time the measurements read the contacts [s] (infinity: never): the next field sample that takes
    /// them, the next row (nextRow, with the series' stress), the next snapshot (nextShot, with the contact network),
    /// the end of the engine's advance (end: the last state's row and snapshot may follow it).
    double contactsWantedAt(double nextRow, double nextShot, double end) const;
    /// The next time a field grid samples [s] (infinity: none).
    double nextTime() const;
    /// The field samples due at world.time (within eps), and the outputs whose window ends there.
    void sample(const World<D>& w, bool contactsValid, double eps);
    /// At a snapshot: the contact network (with [output] contacts).
    void snapshot(const World<D>& w, double time, bool contactsValid);
    /// One event-driven collision (EdmEngine::setObserver).
    void collision(const EdmCollision<D>& c);

    /// For a checkpoint: the grids' sums, their schedules, the collections' entries.
    void saveState(ByteWriter& out) const;
    void loadState(ByteReader& in);

private:
    struct Grid;
    void writeGrid(Grid& g, double time);

    std::filesystem::path dir_;
    bool stress_;
    bool contactsOut_;
    bool wantContacts_ = false;
    std::vector<bool> gridContacts_;  ///< per grid: whether it has contact stress
    std::vector<std::unique_ptr<Grid>> grids_;
    std::vector<std::string> regionNames_;  ///< "" for the domain
    std::vector<CgGrid<D>> regions_;        ///< the domain, then the [[regions]]: boxes of one cell
    ContactSink<D> sink_;
    struct ContactFiles;
    std::unique_ptr<ContactFiles> contactFiles_;
};

extern template class Measures<2>;
extern template class Measures<3>;

}  // namespace haet
