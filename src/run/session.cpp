#include "run/session.hpp"

#include <fmt/format.h>
#include <omp.h>
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <limits>
#include <optional>
#include <ostream>

#include "core/version.hpp"
#include "io/atomic_file.hpp"
#include "io/checkpoint.hpp"
#include "io/json.hpp"
#include "io/series.hpp"
#include "run/checkpoint.hpp"
#include "run/drivers.hpp"
#include "run/export.hpp"
#include "run/flow.hpp"
#include "run/measures.hpp"
#include "run/progress.hpp"
#include "run/run_dir.hpp"
#include "run/schedule.hpp"
#include "run/snapshots.hpp"
#include "run/stop.hpp"
#include "tdm/ranks.hpp"

namespace haet {
namespace {

using Clock = std::chrono::steady_clock;

std::size_t peakRssBytes() {
    rusage ru{};
    getrusage(RUSAGE_SELF, &ru);
    return static_cast<std::size_t>(ru.ru_maxrss) * 1024;
}

/// What a run across ranks does not do yet (docs/parallel.md): each refused with the key to change, before any rank
/// talks to another, so that every rank fails alike (exit 2).
void checkAcrossRanks(const Scenario& sc, const RunOptions& opt, int ranks) {
    auto refuse = [&](const std::string& key, const std::string& what) {
        throw std::invalid_argument(key + ": " + what + " does not run across ranks yet (mpirun -np " +
                                    std::to_string(ranks) + "; docs/parallel.md): run it as one process");
    };
    if (sc.method != Method::Tdm)
        refuse("method", std::string("method = \"") + (sc.method == Method::Edm ? "edm" : "haet") + "\"");
    if (sc.tdm.integrator != IntegratorKind::Verlet) refuse("tdm.integrator", "an integrator other than \"verlet\"");
    for (const WallDef& w : sc.walls)
        if (w.type != WallType::Plane) refuse("walls", "a wall other than a plane (meshes, cylinders, ...)");
    if (!sc.inlets.empty()) refuse("inlet", "an inlet");
    if (!sc.outlets.empty()) refuse("outlet", "an outlet");
    if (!sc.fields.empty()) refuse("fields", "a [[fields]] grid");
    if (!sc.regions.empty()) refuse("regions", "a [[regions]] stress");
    if (sc.output.stress) refuse("output.stress", "the stress tensor of the domain (the default; set it false)");
    if (sc.output.contacts) refuse("output.contacts", "the contact network");
    if (!opt.resumeDir.empty()) refuse("--resume", "resuming from a checkpoint");
    if (!opt.startFrom.empty()) refuse("start", "starting from a checkpoint");
}

std::filesystem::path runDirectory(const Scenario& sc, const RunOptions& opt) {
    if (!opt.resumeDir.empty()) return opt.resumeDir;
    return opt.outDir.empty() ? std::filesystem::path(sc.output.directory) : opt.outDir;
}

template <int D>
class Session final : public RunSession {
public:
    Session(const Scenario& sc, const RunOptions& opt, std::ostream& log)
        : sc_(sc), opt_(opt), log_(log), t0_(Clock::now()), dir_(runDirectory(sc_, opt_)), scope_(opt.stopSignals) {
        if (opt.ranks && opt.ranks->size() > 1) {
            checkAcrossRanks(sc_, opt_, opt.ranks->size());
            ranks_ = opt.ranks;
        }
        if (scope_ == StopScope::Run) signals_.emplace();
        // A resumed run starts from the newest whole checkpoint of its directory (or a script's from a saved file):
        // the World built from the scenario (box, walls, contact table) takes the saved particles, the engine is
        // made on them and takes its own state.
        if (!opt_.resumeDir.empty()) resume_ = findCheckpoint(dir_, sc_, log_);
        const bool startFrom = !opt_.startFrom.empty() && opt_.resumeDir.empty();
        if (startFrom) resume_ = readCheckpoint(opt_.startFrom, sc_);
        world_.emplace(buildWorld<D>(sc_));
        World<D>& world = *world_;
        if (resume_) {
            ByteReader in = resume_->file.section("WRLD");
            loadWorld(in, world);
            in.expectEnd();
        }
        eng_ = makeDriver<D>(sc_, world, StopSignals::flag(), ranks_);
        if (resume_) {
            if (!eng_->restartable())
                throw std::invalid_argument(std::string("--resume: runs of method \"") + eng_->method() +
                                            "\" cannot be resumed yet");
            eng_->loadState(resume_->file);
        }
        plan_ = planRun(sc_, eng_->dt(), world.contact.contactTime);
        if (lead())
            for (const auto& [key, what] : plan_.warnings) log_ << "warning: " << key << ": " << what << "\n";

        // Across ranks rank 0 writes every output, of values reduced over the ranks.
        if ((!resume_ || startFrom) && lead()) prepareRunDirectory(dir_);
        std::vector<std::string> columns = {
            "time",           "step",         "kinetic_energy", "rotational_energy", "potential_energy",
            "elastic_energy", "total_energy", "n_particles",    "n_contacts",        "max_overlap_ratio",
            "pressure",       "momentum_x",   "momentum_y"};
        if (D == 3) columns.push_back("momentum_z");
        for (auto& c : eng_->extraColumns()) columns.push_back(c);
        flow_.emplace(sc_, world, eng_->stepTime());
        if (resume_) {
            ByteReader in = resume_->file.section("FLOW");
            flow_->loadState(in);
        }
        for (auto& c : flow_->columns()) columns.push_back(c);
        // Fields, stress tensors, the contact network (run/measures.hpp), fed by the engine's hooks.
        measures_.emplace(sc_, world, dir_, plan_.snapshotPeriod);
        for (auto& c : measures_->columns()) columns.push_back(c);
        eng_->setCollisionHook([this](const EdmCollision<D>& c) { measures_->collision(c); });
        // The outputs at the start time have their contacts too (a resumed run wrote those before its checkpoint).
        if (!resume_ && measures_->wantsContacts()) eng_->recordStartContacts(measures_->sink());
        lastRowTime_ = world.time;
        // A resumed run's series.csv as the stopped run left it, read before it is rewritten.
        const bool resumeDir = resume_ && !startFrom;
        std::string savedSeries = resumeDir ? readFileText(dir_ / "series.csv") : std::string();
        // A run killed before its end (kill -9, a node lost) leaves run.json saying so; it also proves the
        // directory writable before any time is spent.
        writeRunJson("running");
        if (lead()) {
            series_.emplace(dir_ / "series.csv", columns);
            snaps_.emplace(dir_);
        }

        const bool tty = opt_.progress == ProgressDisplay::On ||
                         (opt_.progress == ProgressDisplay::Auto && !opt_.quiet && isatty(STDERR_FILENO));
        progress_.emplace(tty, sc_.duration);
        eps_ = eng_->timeTolerance();
        rows_ = OutputClock(plan_.seriesPeriod);
        shots_ = OutputClock(plan_.snapshotPeriod);
        ckpts_ = OutputClock(sc_.output.checkpointPeriod);
        // The engine is called in the same pieces whether or not the progress line shows (an event-driven
        // engine's state depends on where its calls end): up to every output time and every 1/500 of the run, at
        // which the progress line may update (at most every 200 ms).
        chunks_ = OutputClock(sc_.duration / 500);
        if (startFrom) {  // new outputs from the saved time on; the state saved is not written again
            ckpts_.pass(world.time, eps_);
            lastCheckpoint_ = world.time;
        }
        if (resumeDir) {
            // The outputs as they were when the checkpoint was written: series.csv up to its rows (a stopped run's
            // last-state row after it is not the schedule's), the collections' entries; the clocks from the times
            // of the last outputs, so that periods changed on resume take effect from here.
            ByteReader in = resume_->file.section("RUN ");
            sequence_ = in.get<std::uint64_t>();
            lastRow_ = in.get<double>();
            lastShot_ = in.get<double>();
            lastRowTime_ = in.get<double>();
            const SeriesMark mark = loadSeriesMark(in);
            snaps_->loadState(in);
            in.expectEnd();
            ByteReader meas = resume_->file.section("MEAS");
            measures_->loadState(meas);
            meas.expectEnd();
            series_->resume(seriesAtCheckpoint(std::move(savedSeries), mark, series_->path(), resume_->path),
                            mark.rows);
            if (lastRow_ >= 0) rows_.pass(lastRow_, eps_);
            if (lastShot_ >= 0) shots_.pass(lastShot_, eps_);
            ckpts_.pass(world.time, eps_);
            lastCheckpoint_ = world.time;
            log_ << "resuming from " << resume_->path.string() << " at t = " << world.time << " s\n";
        }
        checkpoints_ = eng_->restartable() && !ranks_;
        if (!checkpoints_ && sc_.output.checkpointPeriod > 0 && lead())
            log_ << "warning: output.checkpoint_period: runs of method \"" << eng_->method()
                 << "\" write no checkpoints yet\n";
    }

    bool advance(double until) override {
        if (stopped_ || finished_) return false;
        World<D>& world = *world_;
        // A script's run catches the signals only while it advances; a piece after an interrupted one goes on.
        std::optional<StopSignals> during;
        if (scope_ != StopScope::Run) {
            StopSignals::clear();
            if (scope_ == StopScope::Advance && !StopSignals::installed()) {
                try {
                    during.emplace();
                } catch (const std::logic_error&) {  // another thread's run installed them meanwhile
                }
            }
            if (status_ == RunStatus::Interrupted || status_ == RunStatus::Terminated) {
                status_ = RunStatus::Completed;
                statusText_ = "completed";
                stopSignal_ = 0;
            }
        }
        try {
            for (;;) {
                if (rows_.due(world.time, eps_)) {
                    row(OutputClock::stamp(world.time, rows_.next()));
                    rows_.pass(world.time, eps_);
                }
                if (shots_.due(world.time, eps_)) {
                    shot(OutputClock::stamp(world.time, shots_.next()));
                    shots_.pass(world.time, eps_);
                }
                if (measures_->nextTime() <= world.time + eps_) {
                    eng_->synchronise();
                    measures_->sample(world, contactsNow(), eps_);
                }
                if (ckpts_.due(world.time, eps_)) {
                    if (lastCheckpoint_ != world.time) checkpoint();
                    ckpts_.pass(world.time, eps_);
                }
                if (world.time + eps_ >= until || stopAsked()) break;
                // Inlets and outlets act at their own times (Flow::nextTime), between the engine's calls.
                const double target = std::min(
                    {until, rows_.next(), shots_.next(), ckpts_.next(), flow_->nextTime(), measures_->nextTime()});
                // The force pass at the next time the measurements read them records its contacts: at rows and
                // snapshots, and at the end of this call when the last state may be written there (finish). A
                // script's call ends anywhere, its loop of single steps would record at every step (a force pass
                // of its own), so only a call that reaches the scenario's end records at its end; a script that
                // finishes elsewhere writes the last row's stress without contacts, as a run stopped by a signal.
                const double last = scope_ == StopScope::Run || until + eps_ >= sc_.duration
                                        ? until
                                        : std::numeric_limits<double>::infinity();
                if (measures_->wantsContacts())
                    eng_->recordContactsAt(measures_->sink(),
                                           measures_->contactsWantedAt(rows_.next(), shots_.next(), last));
                while (chunks_.due(world.time, eps_)) chunks_.pass(world.time, eps_);
                eng_->advanceTo(chunks_.next() < target - eps_ ? chunks_.next() : target);
                if (world.time + eps_ >= flow_->nextTime()) flow_->act(world, *eng_, eps_);
                progress_->update(world.time, eng_->steps(), eng_->contacts());
            }
        } catch (const SimulationError& e) {
            progress_->finish();
            log_ << "error: simulation stopped: " << e.what() << "\n";
            status_ = RunStatus::BlewUp;
            statusText_ = std::string("failed: ") + e.what();
            stopped_ = true;
        } catch (const IoError& e) {
            // Disk full, directory gone: every file on disk is still a whole one (atomic writes); say so in
            // run.json if that still can be written.
            progress_->finish();
            stopped_ = true;
            try {
                writeRunJson(std::string("failed: output: ") + e.what(), false);
            } catch (const IoError&) {
            }
            throw;
        }
        if (!stopAsked()) return !stopped_;
        noteStop();
        return false;
    }

    RunStatus finish() override {
        if (finished_) return status_;
        finished_ = true;
        World<D>& world = *world_;
        if (scope_ == StopScope::Run && StopSignals::requested()) noteStop();
        if (stopSignal_ != 0 && status_ != RunStatus::BlewUp)
            log_ << (stopSignal_ == SIGINT ? "\nSIGINT" : "\nSIGTERM") << ": stopped at t = " << world.time
                 << " s; writing the last state\n";
        // The last state, always: a checkpoint (before the last row and snapshot, which are not the schedule's: a
        // resumed run drops them), then a row and a snapshot at the time the run ended, unless the schedule just
        // wrote them. A blown-up state is not checkpointed: the last checkpoint stays the newest.
        try {
            if (status_ != RunStatus::BlewUp && lastCheckpoint_ != world.time) checkpoint();
            if (lastRow_ != world.time) row(OutputClock::stamp(world.time, sc_.duration));
            if (lastShot_ != world.time) shot(OutputClock::stamp(world.time, sc_.duration));
        } catch (const SimulationError& e) {  // a blown-up state the engine cannot bring to one time
            log_ << "error: the last state cannot be written: " << e.what() << "\n";
        }
        progress_->update(world.time, eng_->steps(), eng_->contacts(), true);
        progress_->finish();
        if (series_) series_->flush();
        // Across ranks, the last state of every rank's particles on rank 0.
        std::optional<World<D>> all;
        if (ranks_) all.emplace(gathered());
        const World<D>& last = ranks_ ? *all : world;
        // The state for a next stage (run/export.hpp): disks and spheres, unless the run blew up.
        if (lead() && status_ != RunStatus::BlewUp && !last.particles.hasPolygons() && last.particles.hasMotion()) {
            writeStateCsv(dir_ / "final.csv", last, sc_.materials);
            writeLammpsData(dir_ / "final.data", last, sc_.materials);
        }
        writeRunJson(statusText_);
        if (lead()) writeFinalPicture(sc_, last, eng_->hybrid(), dir_ / "final.png");
        if (!opt_.quiet) {
            const double wall = std::chrono::duration<double>(Clock::now() - t0_).count();
            log_ << fmt::format("{} ({}): {} particles, simulated {:.4g} s in {:.2f} s wall time; outputs in {}\n",
                                sc_.name, eng_->method(), last.particles.size(), world.time, wall, dir_.string());
        }
        return status_;
    }

    double time() const override { return world_->time; }
    std::uint64_t steps() const override { return eng_->steps(); }
    RunStatus status() const override { return status_; }
    std::string statusText() const override { return statusText_; }
    const Scenario& scenario() const override { return sc_; }
    void synchronise() override { eng_->synchronise(); }
    double dt() const override { return eng_->dt(); }
    const char* method() const override { return eng_->method(); }
    const std::filesystem::path& directory() const override { return dir_; }
    void flush() override {
        if (series_) series_->flush();
    }
    void setStopScope(StopScope scope) override {
        if (scope_ == StopScope::Run || scope == StopScope::Run)
            throw std::logic_error("RunSession: the signals of `haet run` are caught for its whole life");
        scope_ = scope;
    }
    void stateChanged() override { eng_->stateChanged(); }
    void added(std::size_t first) override { eng_->added(first); }
    std::uint64_t takeIds(std::uint64_t n) override { return flow_->takeIds(n); }
    void remove(const std::vector<std::uint32_t>& which) override { eng_->remove(which); }
    void save(const std::filesystem::path& file) override {
        if (!checkpoints_)
            throw std::invalid_argument(std::string("runs of method \"") + eng_->method() +
                                        "\" cannot be checkpointed yet");
        writeFileAtomic(file, checkpointBytes(sequence_ + 1));
        eng_->synchronise();
    }

protected:
    World<2>* world2() override {
        if constexpr (D == 2) return &*world_;
        return nullptr;
    }
    World<3>* world3() override {
        if constexpr (D == 3) return &*world_;
        return nullptr;
    }

private:
    /// Rank 0 of a run across ranks, or the one process: who writes the outputs.
    bool lead() const { return !ranks_ || ranks_->rank() == 0; }

    /// Whether the run is to stop (SIGINT, SIGTERM): across ranks, whether any rank caught one, so all stop alike.
    bool stopAsked() const { return ranks_ ? ranks_->any(StopSignals::requested()) : StopSignals::requested(); }

    /// Across ranks: a World like this rank's with every rank's own particles, on rank 0 (other ranks: none), in
    /// order of id. Collective.
    World<D> gathered() const {
        const World<D>& w = *world_;
        World<D> all;
        all.particles = gatherParticles(*ranks_, w.particles, std::min(eng_->owned(), w.particles.size()));
        all.domain = w.domain;
        all.walls = w.walls;
        all.surfaces = w.surfaces;
        all.contact = w.contact;
        all.time = w.time;
        return all;
    }

    /// The particles of the run, over every rank. Collective across ranks.
    std::size_t totalParticles() {
        const World<D>& w = *world_;
        if (!ranks_) return w.particles.size();
        std::vector<double> n{double(std::min(eng_->owned(), w.particles.size())), eng_->migrated()};
        ranks_->sum(n);
        total_ = static_cast<std::size_t>(n[0]);
        migrated_ = n[1];
        return total_;
    }

    std::vector<std::optional<double>> rowValues(double stamp) {
        const World<D>& world = *world_;
        Energies<D> e = energies(world, eng_->owned());
        double elastic = eng_->elasticEnergy();
        const double window = world.time - lastRowTime_;
        lastRowTime_ = world.time;
        std::optional<double> pressure;
        const double vir = eng_->virial(window);
        double contacts = double(eng_->contacts()), overlap = eng_->maxOverlapRatio();
        double count = double(world.particles.size());
        if (ranks_) {
            // Sums over the ranks, each of its own particles and its share of the contacts. The pressure is left
            // out: a pair across a boundary is in the virial of both ranks (docs/parallel.md).
            std::vector<double> v{e.kinetic,
                                  e.rotational,
                                  e.potential,
                                  e.mv2,
                                  elastic,
                                  eng_->contactShare(),
                                  double(std::min(eng_->owned(), world.particles.size()))};
            for (int k = 0; k < D; ++k) v.push_back(e.momentum[k]);
            ranks_->sum(v);
            e.kinetic = v[0];
            e.rotational = v[1];
            e.potential = v[2];
            e.mv2 = v[3];
            elastic = v[4];
            contacts = std::round(v[5]);
            count = v[6];
            total_ = static_cast<std::size_t>(count);
            for (int k = 0; k < D; ++k) e.momentum[k] = v[7 + k];
            std::vector<double> worst{overlap};
            ranks_->max(worst);
            overlap = worst[0];
        } else if (world.domain.fullyPeriodic()) {
            pressure = (e.mv2 + vir) / (D * world.domain.volume());
        }
        std::vector<std::optional<double>> row = {stamp,
                                                  double(eng_->steps()),
                                                  e.kinetic,
                                                  e.rotational,
                                                  e.potential,
                                                  elastic,
                                                  e.kinetic + e.rotational + e.potential + elastic,
                                                  count,
                                                  contacts,
                                                  overlap,
                                                  pressure};
        for (int k = 0; k < D; ++k) row.push_back(e.momentum[k]);
        for (auto& v : eng_->extraRow()) row.push_back(v);
        for (auto& v : flow_->row(world.time)) row.push_back(v);
        for (auto& v : measures_->row(world, contactsNow(), window)) row.push_back(v);
        return row;
    }

    /// Whether the force pass at the current time recorded its contacts (the measurements read them).
    bool contactsNow() const { return measures_->wantsContacts() && eng_->contactsRecordedAt() == world_->time; }

    void row(double stamp) {
        eng_->synchronise();
        std::vector<std::optional<double>> values = rowValues(stamp);
        if (series_) series_->row(std::move(values));
        lastRow_ = world_->time;
    }

    void shot(double stamp) {
        eng_->synchronise();
        if (ranks_) {  // gathered on rank 0, one file as from one process (docs/parallel.md)
            const World<D> all = gathered();
            if (lead()) snaps_->write(all, stamp, nullptr);
        } else {
            snaps_->write(*world_, stamp, eng_->hybrid());
            measures_->snapshot(*world_, stamp, contactsNow());
        }
        if (series_) series_->flush();
        lastShot_ = world_->time;
    }

    /// The first signal that stopped the run: the outcome it gives.
    void noteStop() {
        if (status_ == RunStatus::BlewUp) return;
        stopSignal_ = StopSignals::signal();
        status_ = stopSignal_ == SIGINT ? RunStatus::Interrupted : RunStatus::Terminated;
        statusText_ = "interrupted";
        if (scope_ == StopScope::Run) stopped_ = true;
    }

    /// A checkpoint: the whole state at world.time and the outputs written so far (series.csv flushed first, so
    /// that the file on disk always holds at least the rows a checkpoint counts).
    void checkpoint() {
        if (!checkpoints_) return;
        const auto start = Clock::now();
        const std::string file = checkpointBytes(++sequence_);
        writeCheckpoint(dir_, sequence_, file);
        lastCheckpoint_ = world_->time;
        ckptBook_.written += 1;
        ckptBook_.bytes = file.size();
        ckptBook_.seconds += std::chrono::duration<double>(Clock::now() - start).count();
    }

    /// The bytes of checkpoint number `sequence` of the state now.
    std::string checkpointBytes(std::uint64_t sequence) {
        const World<D>& world = *world_;
        eng_->exposeState();
        series_->flush();
        ByteWriter body;
        body.beginSection("SCEN");
        body.putString(sc_.stateKeys);
        body.endSection();
        body.beginSection("WRLD");
        saveWorld(body, world);
        body.endSection();
        body.beginSection("ENGN");
        eng_->saveState(body);
        body.endSection();
        body.beginSection("FLOW");
        flow_->saveState(body);
        body.endSection();
        body.beginSection("MEAS");
        measures_->saveState(body);
        body.endSection();
        body.beginSection("RUN ");
        body.put<std::uint64_t>(sequence);
        body.put<double>(lastRow_);
        body.put<double>(lastShot_);
        body.put<double>(lastRowTime_);
        saveSeriesMark(body, *series_);
        snaps_->saveState(body);
        body.endSection();
        CheckpointHeader h;
        h.dimension = D;
        h.method = eng_->method();
        h.scenarioHash = sc_.stateHash;
        h.time = world.time;
        h.sequence = sequence;
        return encodeCheckpoint(h, body.bytes());
    }

    /// run.json (rank 0). count: count the particles over the ranks first (collective), else the last count.
    void writeRunJson(const std::string& status, bool count = true) {
        const World<D>& world = *world_;
        const std::size_t particles = ranks_ ? (count ? totalParticles() : total_) : world.particles.size();
        if (!lead()) return;
        const double wall = std::chrono::duration<double>(Clock::now() - t0_).count();
        JsonObject j;
        j.add("version", kVersion);
        j.add("scenario", sc_.path);
        j.add("scenario_name", sc_.name);
        j.add("scenario_hash", sc_.hash);
        if (!sc_.overrides.empty()) {  // --set KEY=VALUE, applied to the file in this order
            JsonObject o;
            for (const std::string& kv : sc_.overrides) o.add(kv.substr(0, kv.find('=')), kv.substr(kv.find('=') + 1));
            j.add("overrides", o);
        }
        j.add("method", eng_->method());
        if (resume_) {  // the checkpoint this run went on from
            j.add("resumed_from", resume_->path.filename().string());
            j.add("resumed_at", resume_->file.header.time);
        }
        j.add("dimension", static_cast<std::int64_t>(D));
        {  // what `haet render` needs besides the snapshots: the box, the materials' names, the picture's settings
            const PictureBox box = pictureBox(world);
            JsonObject d, pic;
            d.add("lo", std::vector<double>(box.lo.begin(), box.lo.begin() + D));
            d.add("hi", std::vector<double>(box.hi.begin(), box.hi.begin() + D));
            d.add("gravity", std::vector<double>(box.gravity.begin(), box.gravity.begin() + D));
            j.add("domain", d);
            j.add("materials", materialNames(sc_));
            const PictureOptions po = pictureOptions(sc_);
            pic.add("color_by", po.colorBy);
            if (po.range) pic.add("color_range", std::vector<double>(po.range->begin(), po.range->end()));
            pic.add("view", std::vector<double>(po.view.begin(), po.view.end()));
            pic.add("width", static_cast<std::int64_t>(po.widthPx));
            j.add("picture", pic);
        }
        j.add("status", status);
        j.add("n_particles", particles);
        if (ranks_) {
            j.add("ranks", static_cast<std::int64_t>(ranks_->size()));
            j.add("migrated", static_cast<std::uint64_t>(
                                  migrated_));  // particles handed from one rank's slab to another's, over the run
        }
        j.add("contact_time", world.contact.contactTime);
        j.add("simulated_time", world.time);
        j.add("steps", eng_->steps());
        eng_->describe(j);
        flow_->describe(j);
        if (!plan_.warnings.empty()) {  // what the run warned of on stderr, by the key concerned
            JsonObject w;
            for (const auto& [key, what] : plan_.warnings) w.add(key, what);
            j.add("warnings", w);
        }
        if (ckptBook_.written > 0) {  // what the checkpoints of this run cost: their count, last size, time
            JsonObject c;
            c.add("written", ckptBook_.written);
            c.add("last_bytes", ckptBook_.bytes);
            c.add("seconds", ckptBook_.seconds);
            j.add("checkpoints", c);
        }
        j.add("wall_time", wall);
        j.add("particle_steps_per_second", wall > 0 ? double(eng_->steps()) * particles / wall : 0.0);
        j.add("threads", static_cast<std::int64_t>(omp_get_max_threads()));
        j.add("peak_rss_bytes", peakRssBytes());
        writeFileAtomic(dir_ / "run.json", j.dump() + "\n");
    }

    // Declared in the order they are made: the scenario is a copy, so that a session outlives its caller's.
    const Scenario sc_;
    const RunOptions opt_;
    std::ostream& log_;
    const Clock::time_point t0_;
    const std::filesystem::path dir_;
    std::optional<ResumePoint> resume_;
    StopScope scope_;
    std::optional<World<D>> world_;
    std::optional<StopSignals> signals_;  // StopScope::Run: for the session's life
    int stopSignal_ = 0;                  // the signal that stopped it (0: none)
    Ranks* ranks_ = nullptr;              // across ranks (more than one); null in one process
    std::size_t total_ = 0;               // across ranks: the particles over all ranks at the last count
    double migrated_ = 0;                 // across ranks: the migrations over all ranks at the last count
    std::unique_ptr<Driver<D>> eng_;
    RunPlan plan_;
    std::optional<Flow<D>> flow_;
    std::optional<SeriesWriter> series_;
    std::optional<SnapshotWriter<D>> snaps_;
    std::optional<Measures<D>> measures_;
    std::optional<Progress> progress_;
    double eps_ = 0;
    OutputClock rows_{0}, shots_{0}, ckpts_{0}, chunks_{0};
    double lastRowTime_ = 0;               // engine time of the last row's window start [s]
    double lastRow_ = -1, lastShot_ = -1;  // engine times of the last row and snapshot written
    double lastCheckpoint_ = -1;           // engine time of the last checkpoint
    std::uint64_t sequence_ = 0;           // of the last checkpoint written
    bool checkpoints_ = false;
    struct {
        std::uint64_t written = 0, bytes = 0;
        double seconds = 0;  // wall time spent making and writing them [s]
    } ckptBook_;
    RunStatus status_ = RunStatus::Completed;
    std::string statusText_ = "completed";
    bool stopped_ = false, finished_ = false;
};

}  // namespace

std::unique_ptr<RunSession> RunSession::open(const Scenario& sc, const RunOptions& opt, std::ostream& log) {
    if (opt.threads > 0) omp_set_num_threads(opt.threads);
    if (sc.dimension == 2) return std::make_unique<Session<2>>(sc, opt, log);
    return std::make_unique<Session<3>>(sc, opt, log);
}

}  // namespace haet
