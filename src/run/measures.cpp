#include "run/measures.hpp"

#include <fmt/compile.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <numbers>

#include "io/atomic_file.hpp"
#include "io/vtk.hpp"
#include "run/checkpoint.hpp"
#include "run/schedule.hpp"

namespace haet {

namespace {

constexpr const char* kAxes = "xyz";

/// The volume of particle i (2D: its area) [m^D].
template <int D>
double particleVolume(const Particles<D>& p, std::size_t i) {
    const double r = p.radius[i];
    if constexpr (D == 2) {
        if (p.isPolygon(i)) return p.shapes.area[p.shape[i]];
        return std::numbers::pi * r * r;
    } else {
        return 4.0 / 3.0 * std::numbers::pi * r * r * r;
    }
}

/// A box's grid spec: along a periodic axis that it spans the kernel wraps; one that it covers in part sees the
/// particles' and branches' periodic images that reach into it.
template <int D>
void boxOf(CgGridSpec<D>& s, const Domain<D>& dom, const Vec3d& lo, const Vec3d& hi) {
    for (int k = 0; k < D; ++k) {
        s.lo[k] = lo[k];
        s.hi[k] = hi[k];
        s.wraps[k] = dom.periodic[k] && lo[k] <= dom.lo[k] && hi[k] >= dom.hi[k];
        s.period[k] = dom.periodic[k] && !s.wraps[k] ? dom.hi[k] - dom.lo[k] : 0.0;
    }
}

template <int D>
void addParticles(CgGrid<D>& g, const Particles<D>& p) {
    const std::size_t nTdm = p.tdmCount();
    for (std::size_t i = 0; i < p.size(); ++i) g.addParticle(p.x[i], p.mass[i], particleVolume(p, i), i < nTdm, p.v[i]);
}

template <int D>
void addContacts(CgGrid<D>& g, const ContactSink<D>& sink) {
    for (const ContactRecord<D>& r : sink) g.addContact(r.position, r.branch, r.fn + r.ft);
}

/// The names of a field's components: "" (scalar), "_x" ... (vector), "_xx" ... (tensor).
std::vector<std::string> componentNames(int comps, int dim) {
    if (comps == 1) return {""};
    std::vector<std::string> out;
    if (comps == dim)
        for (int a = 0; a < dim; ++a) out.push_back(std::string("_") + kAxes[a]);
    else
        for (int a = 0; a < dim; ++a)
            for (int b = 0; b < dim; ++b) out.push_back(std::string("_") + kAxes[a] + kAxes[b]);
    return out;
}

}  // namespace

/// One [[fields]] block at run time: its grid, its samples' schedule, its files.
template <int D>
struct Measures<D>::Grid {
    FieldsDef def;
    CgGrid<D> cg;
    double period, window, collisionWindow;
    int samplesPerWindow;  ///< m: samples j = 0..m, the last at the output time
    std::int64_t k = 0;    ///< the next output: k x period
    int j = 0;             ///< its next sample
    PvdCollection pvd;
    std::int64_t files = 0;  ///< outputs written
    std::string csv;         ///< fields_NAME.csv (1-axis grids)

    Grid(const FieldsDef& d, const CgGridSpec<D>& spec, double per, const std::filesystem::path& dir)
        : def(d), cg(spec), period(per), window(d.window), pvd(dir / ("fields_" + d.name + ".pvd")) {
        collisionWindow = window > 0 ? window : period;
        samplesPerWindow = 0;
        if (window > 0) {
            const double interval = d.sampleInterval > 0 ? d.sampleInterval : window / 10;
            samplesPerWindow = std::max(1, static_cast<int>(std::lround(window / interval)));
        }
    }
    double outputTime(std::int64_t kk) const { return static_cast<double>(kk) * period; }
    /// Sample j of output k: the window's whole intervals, the last at the output time exactly.
    double sampleTime(std::int64_t kk, int jj) const {
        if (jj >= samplesPerWindow) return outputTime(kk);
        return outputTime(kk) - window + window * jj / samplesPerWindow;
    }
    double next() const { return sampleTime(k, j); }
    /// The schedule from time t on: the first sample not before t.
    void startAt(double t, double eps) {
        k = static_cast<std::int64_t>(std::ceil((t - eps) / period));
        if (k < 0) k = 0;
        j = 0;
        while (sampleTime(k, j) < t - eps) ++j;
    }
};

template <int D>
struct Measures<D>::ContactFiles {
    PvdCollection pvd;
    std::int64_t count = 0;
    explicit ContactFiles(const std::filesystem::path& dir) : pvd(dir / "contacts.pvd") {}
};

template <int D>
Measures<D>::Measures(const Scenario& sc, const World<D>& w, std::filesystem::path dir, double snapshotPeriod)
    : dir_(std::move(dir)), stress_(sc.output.stress), contactsOut_(sc.output.contacts && snapshotPeriod >= 0) {
    for (const FieldsDef& d : sc.fields) {
        CgGridSpec<D> spec;
        spec.nAxes = d.nAxes;
        // Grid axes in the box's order, so that cells go x fastest as VTK image data does.
        std::array<std::pair<int, int>, 3> ax;
        for (int a = 0; a < d.nAxes; ++a) ax[a] = {d.axes[a], d.cells[a]};
        std::sort(ax.begin(), ax.begin() + d.nAxes);
        for (int a = 0; a < d.nAxes; ++a) {
            spec.axis[a] = ax[a].first;
            spec.cells[a] = ax[a].second;
        }
        boxOf(spec, w.domain, d.lo, d.hi);
        spec.kernel = d.kernel;
        spec.width = d.width;
        spec.cutoff = d.cutoff;
        spec.branchNodes = d.branchNodes;
        const double period = d.period > 0 ? d.period : (snapshotPeriod > 0 ? snapshotPeriod : sc.duration / 20);
        auto g = std::make_unique<Grid>(d, spec, period, dir_);
        g->startAt(w.time, 0);
        const bool contacts = d.fields & ((1u << 5) | (1u << 7));  // contact_stress, stress
        gridContacts_.push_back(contacts);
        wantContacts_ = wantContacts_ || contacts;
        grids_.push_back(std::move(g));
    }
    if (stress_) {
        wantContacts_ = true;
        auto region = [&](const std::string& name, const Vec3d& lo, const Vec3d& hi) {
            CgGridSpec<D> s;
            s.nAxes = 1;
            s.axis = {0, 1, 2};
            s.cells = {1, 1, 1};
            boxOf(s, w.domain, lo, hi);
            s.width = 0;  // the box: whole particles, branches cut at its faces
            regionNames_.push_back(name);
            regions_.emplace_back(s);
        };
        Vec3d dlo{0, 0, 0}, dhi{0, 0, 0};
        for (int k = 0; k < D; ++k) {
            dlo[k] = w.domain.lo[k];
            dhi[k] = w.domain.hi[k];
        }
        region("", dlo, dhi);
        for (const RegionDef& r : sc.regions) region(r.name, r.lo, r.hi);
    }
    if (contactsOut_) {
        wantContacts_ = true;
        contactFiles_ = std::make_unique<ContactFiles>(dir_);
    }
}

template <int D>
Measures<D>::~Measures() = default;

template <int D>
std::vector<std::string> Measures<D>::columns() const {
    std::vector<std::string> c;
    for (const std::string& name : regionNames_)
        for (const std::string& comp : componentNames(D * D, D))
            c.push_back((name.empty() ? "" : name + "_") + "stress" + comp);
    return c;
}

template <int D>
std::vector<std::optional<double>> Measures<D>::row(const World<D>& w, bool contactsValid, double window) {
    std::vector<std::optional<double>> out;
    for (CgGrid<D>& g : regions_) {
        addParticles(g, w.particles);
        if (contactsValid) addContacts(g, sink_);
        g.endSample();
        const CgFields<D> f = g.fields(window);
        for (int e = 0; e < D * D; ++e) out.emplace_back(f.stress[e]);
        g.clear();
    }
    return out;
}

template <int D>
double Measures<D>::nextTime() const {
    double t = std::numeric_limits<double>::infinity();
    for (const auto& g : grids_) t = std::min(t, g->next());
    return t;
}

template <int D>
double Measures<D>::contactsWantedAt(double nextRow, double nextShot, double end) const {
    double t = std::numeric_limits<double>::infinity();
    for (std::size_t g = 0; g < grids_.size(); ++g)
        if (gridContacts_[g]) t = std::min(t, grids_[g]->next());
    if (stress_) t = std::min(t, nextRow);
    if (contactsOut_) t = std::min(t, nextShot);
    if (stress_ || contactsOut_) t = std::min(t, end);  // the last state's row and snapshot
    return t;
}

template <int D>
void Measures<D>::sample(const World<D>& w, bool contactsValid, double eps) {
    for (auto& gp : grids_) {
        Grid& g = *gp;
        if (g.next() > w.time + eps) continue;
        addParticles(g.cg, w.particles);
        if (contactsValid) addContacts(g.cg, sink_);
        g.cg.endSample();
        if (g.j < g.samplesPerWindow) {
            ++g.j;
            continue;
        }
        writeGrid(g, OutputClock::stamp(w.time, g.outputTime(g.k)));
        g.cg.clear();
        ++g.k;
        g.j = 0;
        while (g.sampleTime(g.k, g.j) < w.time + eps) ++g.j;  // a window that began before this time
        if (g.j > g.samplesPerWindow) g.startAt(w.time + 2 * eps, 0);
    }
}

template <int D>
void Measures<D>::collision(const EdmCollision<D>& c) {
    for (auto& gp : grids_) {
        Grid& g = *gp;
        if (c.time > g.outputTime(g.k) - g.collisionWindow) g.cg.addCollision(c.position, c.branch, c.impulse);
    }
    for (CgGrid<D>& g : regions_) g.addCollision(c.position, c.branch, c.impulse);
}

template <int D>
void Measures<D>::writeGrid(Grid& g, double time) {
    const CgGridSpec<D>& s = g.cg.spec();
    const CgFields<D> f = g.cg.fields(time > 0 ? std::min(g.collisionWindow, time) : 0.0);
    const std::size_t n = f.cells;
    // VTK wants 3-vectors and 3 x 3 tensors: 2D ones padded with zeros.
    auto pad = [&](const std::vector<double>& v, int comps) {
        const int out = comps == D ? 3 : 9;
        std::vector<double> r(n * static_cast<std::size_t>(out), 0.0);
        for (std::size_t c = 0; c < n; ++c)
            for (int a = 0; a < D; ++a) {
                if (comps == D) {
                    r[c * 3 + a] = v[c * D + a];
                } else {
                    for (int b = 0; b < D; ++b) r[c * 9 + a * 3 + b] = v[c * D * D + a * D + b];
                }
            }
        return r;
    };
    struct Out {
        const char* name;
        int comps;
        const std::vector<double>* values;
    };
    const Out all[9] = {{"density", 1, &f.density},
                        {"volume_fraction", 1, &f.volumeFraction},
                        {"velocity", D, &f.velocity},
                        {"kinetic_stress", D * D, &f.kineticStress},
                        {"temperature", 1, &f.temperature},
                        {"contact_stress", D * D, &f.contactStress},
                        {"collisional_stress", D * D, &f.collisionalStress},
                        {"stress", D * D, &f.stress},
                        {"mode_fraction", 1, &f.modeFraction}};
    std::vector<std::vector<double>> padded;
    padded.reserve(9);
    std::vector<VtkField> cells;
    for (int q = 0; q < 9; ++q) {
        if (!(g.def.fields & (1u << q))) continue;
        const Out& o = all[q];
        if (o.comps == 1) {
            cells.push_back({o.name, 1, VtkField::Float64, o.values->data()});
        } else {
            padded.push_back(pad(*o.values, o.comps));
            cells.push_back({o.name, o.comps == D ? 3 : 9, VtkField::Float64, padded.back().data()});
        }
    }
    std::array<int, 3> dims{1, 1, 1};
    std::array<double, 3> origin{0, 0, 0}, spacing{1, 1, 1};
    for (int k = 0; k < D; ++k) {
        origin[k] = s.lo[k];
        spacing[k] = s.hi[k] - s.lo[k];
    }
    for (int a = 0; a < s.nAxes; ++a) {
        dims[s.axis[a]] = s.cells[a];
        spacing[s.axis[a]] = (s.hi[s.axis[a]] - s.lo[s.axis[a]]) / s.cells[a];
    }
    const std::string name = fmt::format("fields_{}_{:06d}.vti", g.def.name, g.files);
    writeVtiCells(dir_ / name, dims, origin, spacing, cells, time);
    g.pvd.add(time, name);
    ++g.files;
    if (s.nAxes == 1) {  // profiles: one row per cell and output
        if (g.csv.empty()) {
            g.csv = std::string("time,") + kAxes[s.axis[0]];
            for (int q = 0; q < 9; ++q)
                if (g.def.fields & (1u << q))
                    for (const std::string& c : componentNames(all[q].comps, D))
                        g.csv += "," + std::string(all[q].name) + c;
            g.csv += "\n";
        }
        for (std::size_t c = 0; c < n; ++c) {
            auto to = std::back_inserter(g.csv);
            fmt::format_to(to, FMT_COMPILE("{},{}"), time, g.cg.cellCentre(0, static_cast<int>(c)));
            for (int q = 0; q < 9; ++q)
                if (g.def.fields & (1u << q))
                    for (int e = 0; e < all[q].comps; ++e)
                        fmt::format_to(to, FMT_COMPILE(",{}"),
                                       (*all[q].values)[c * static_cast<std::size_t>(all[q].comps) + e]);
            g.csv += "\n";
        }
        writeFileAtomic(dir_ / ("fields_" + g.def.name + ".csv"), g.csv);
    }
}

template <int D>
void Measures<D>::snapshot(const World<D>& w, double time, bool contactsValid) {
    if (!contactFiles_) return;
    ContactFiles& cf = *contactFiles_;
    const ContactSink<D> none;
    const ContactSink<D>& recs = contactsValid ? sink_ : none;
    const std::size_t n = recs.size();
    std::vector<double> xyz(6 * n, 0.0), fn(3 * n, 0.0), ft(3 * n, 0.0), nrm(3 * n, 0.0), overlap(n), force(n);
    std::vector<std::int64_t> id1(n), id2(n);
    std::vector<std::int32_t> wall(n);
    std::string csv = D == 3 ? "id1,id2,wall,x,y,z,nx,ny,nz,fn_x,fn_y,fn_z,ft_x,ft_y,ft_z,overlap\n"
                             : "id1,id2,wall,x,y,nx,ny,fn_x,fn_y,ft_x,ft_y,overlap\n";
    for (std::size_t c = 0; c < n; ++c) {
        const ContactRecord<D>& r = recs[c];
        const bool isWall = r.j == ContactRecord<D>::kWall;
        // The line: from the centre of i to the centre of j (its image by the branch), or to the wall's point.
        const Vec<D> end = isWall ? r.point : r.position - r.branch;
        for (int k = 0; k < D; ++k) {
            xyz[6 * c + k] = r.position[k];
            xyz[6 * c + 3 + k] = end[k];
            fn[3 * c + k] = r.fn[k];
            ft[3 * c + k] = r.ft[k];
            nrm[3 * c + k] = r.normal[k];
        }
        overlap[c] = r.overlap;
        force[c] = norm(r.fn + r.ft);
        id1[c] = static_cast<std::int64_t>(r.idI);
        id2[c] = isWall ? -1 : static_cast<std::int64_t>(r.idJ);
        wall[c] = isWall ? r.wall : -1;
        // Formats compiled once (a snapshot writes some 10^4 numbers per thousand contacts).
        auto to = std::back_inserter(csv);
        fmt::format_to(to, FMT_COMPILE("{},{},{}"), id1[c], id2[c], wall[c]);
        for (const Vec<D>* v : {&r.point, &r.normal, &r.fn, &r.ft})
            for (int k = 0; k < D; ++k) fmt::format_to(to, FMT_COMPILE(",{}"), (*v)[k]);
        fmt::format_to(to, FMT_COMPILE(",{}\n"), r.overlap);
    }
    (void)w;
    const std::string vtp = fmt::format("contacts_{:06d}.vtp", cf.count);
    writeVtpLines(dir_ / vtp, xyz,
                  {{"id1", 1, VtkField::Int64, id1.data()},
                   {"id2", 1, VtkField::Int64, id2.data()},
                   {"wall", 1, VtkField::Int32, wall.data()},
                   {"normal", 3, VtkField::Float64, nrm.data()},
                   {"normal_force", 3, VtkField::Float64, fn.data()},
                   {"tangential_force", 3, VtkField::Float64, ft.data()},
                   {"force", 1, VtkField::Float64, force.data()},
                   {"overlap", 1, VtkField::Float64, overlap.data()}},
                  time);
    writeFileAtomic(dir_ / fmt::format("contacts_{:06d}.csv", cf.count), csv);
    cf.pvd.add(time, vtp);
    ++cf.count;
}

template <int D>
void Measures<D>::saveState(ByteWriter& out) const {
    out.put<std::uint64_t>(grids_.size());
    for (const auto& gp : grids_) {
        const Grid& g = *gp;
        out.put<std::int64_t>(g.k);
        out.put<std::int32_t>(g.j);
        out.put<std::int64_t>(g.files);
        out.put<std::uint64_t>(g.cg.samples());
        out.putVector(g.cg.sums());
        out.putString(g.csv);
        savePvd(out, g.pvd);
    }
    out.put<std::uint64_t>(regions_.size());
    for (const CgGrid<D>& g : regions_) out.putVector(g.sums());  // the collisions since the last row
    out.put<std::uint8_t>(contactFiles_ != nullptr);
    if (contactFiles_) {
        out.put<std::int64_t>(contactFiles_->count);
        savePvd(out, contactFiles_->pvd);
    }
}

template <int D>
void Measures<D>::loadState(ByteReader& in) {
    if (in.get<std::uint64_t>() != grids_.size()) in.fail("the [[fields]] blocks differ from the checkpoint's");
    for (auto& gp : grids_) {
        Grid& g = *gp;
        g.k = in.get<std::int64_t>();
        g.j = in.get<std::int32_t>();
        g.files = in.get<std::int64_t>();
        if (g.k < 0 || g.j < 0 || g.j > g.samplesPerWindow || g.files < 0) in.fail("a field grid's schedule");
        g.cg.setSamples(in.get<std::uint64_t>());
        std::vector<double> sums;
        in.getVector(sums, g.cg.sums().size(), "a field grid's sums");
        g.cg.sums() = std::move(sums);
        g.csv = in.getString();
        loadPvd(in, g.pvd);
        if (!g.csv.empty()) writeFileAtomic(dir_ / ("fields_" + g.def.name + ".csv"), g.csv);
    }
    if (in.get<std::uint64_t>() != regions_.size()) in.fail("the [[regions]] differ from the checkpoint's");
    for (CgGrid<D>& g : regions_) {
        std::vector<double> sums;
        in.getVector(sums, g.sums().size(), "a region's sums");
        g.sums() = std::move(sums);
    }
    const bool cf = in.get<std::uint8_t>() != 0;
    if (cf != (contactFiles_ != nullptr)) in.fail("[output] contacts differs from the checkpoint's");
    if (contactFiles_) {
        contactFiles_->count = in.get<std::int64_t>();
        loadPvd(in, contactFiles_->pvd);
    }
}

template class Measures<2>;
template class Measures<3>;

}  // namespace haet
