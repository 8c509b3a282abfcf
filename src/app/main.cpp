// The `haet` command line: run and check scenarios, render a run's snapshots, plot CSV tables. Exit codes
// (docs/scenario.md, "Running"): 0 ok, 1 an unexpected failure, 2 bad input, 3 the simulation blew up, 4 an output
// could not be written, 130 / 143 a run stopped by SIGINT / SIGTERM.
#include <malloc.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <array>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "core/version.hpp"
#include "io/atomic_file.hpp"
#include "io/checkpoint.hpp"
#include "io/png.hpp"
#include "io/table.hpp"
#include "run/ranks_mpi.hpp"
#include "run/render.hpp"
#include "run/runner.hpp"
#include "scenario/loader.hpp"

namespace {

/// OpenMP threads that wait by spinning starve the other work of a shared, loaded machine and each other: the hybrid
/// demo took 364 s of wall time on two threads beside a competing load, 63 s on one, and 44 s on two with passive
/// waiting (a waiting thread sleeps at once). libgomp reads OMP_WAIT_POLICY when it is loaded, before main, so the
/// program sets it (unless the user has) and executes itself again; the same process, pid and arguments.
void passiveOpenMpWaiting(char** argv) {
    if (std::getenv("OMP_WAIT_POLICY") != nullptr) return;
    if (setenv("OMP_WAIT_POLICY", "passive", 0) != 0) return;
    // The binary's own path rather than /proc/self/exe, so that the process keeps its name (ps, top, pkill haet).
    std::array<char, 4096> self{};
    const ssize_t n = readlink("/proc/self/exe", self.data(), self.size() - 1);
    execv(n > 0 ? self.data() : "/proc/self/exe", argv);  // returns only if it failed: then run on as before
}

}  // namespace

/// The command; *thrown: whether it ended by an exception (an error that may be this rank's alone).
int runCommand(int argc, char** argv, haet::MpiScope& mpi, bool* thrown);

int main(int argc, char** argv) {
    passiveOpenMpWaiting(argv);
    // After the program has executed itself again: MPI is initialised once, in the process that runs.
    haet::MpiScope mpi(argc, argv);
    bool thrown = false;
    const int code = runCommand(argc, argv, mpi, &thrown);
    // An error thrown after the ranks started talking may be one rank's alone (an output rank 0 cannot write): the
    // others wait in a collective, so all end at once, with the same exit code. Before that, every rank read the same
    // input and fails alike; a blow-up or a signal the ranks agree on (run/session.cpp). MPI is finalised as the
    // scope ends.
    if (thrown && mpi.talking()) mpi.abort(code);
    return code;
}

int runCommand(int argc, char** argv, haet::MpiScope& mpi, bool* thrown) {
    // Large buffers (pair lists rebuilt every ~100 steps, file contents at set-up) go straight to the system
    // and back when freed. By default glibc raises this threshold to the size of the last freed buffer, after
    // which buffers come from the heap and the freed ones stay resident (3D chute benchmark, 1 500 steps: peak
    // resident memory 30.8 MB with the default, 27.8 MB with this).
    mallopt(M_MMAP_THRESHOLD, 256 * 1024);
    CLI::App app{"HAET: granular flows with time-driven DEM, event-driven dynamics and their hybrid"};
    app.set_version_flag("--version", std::string("haet ") + haet::kVersion);
    app.require_subcommand(1);

    std::string runFile, outDir, resumeDir;
    std::vector<std::string> sets;  // --set KEY=VALUE of `run` or `check`, in order
    int threads = 0;
    bool quiet = false, progress = false;
    const std::string setHelp =
        "override a value of the scenario, KEY=VALUE with a TOML value (tdm.dt=1e-5, insert[2].count=500); "
        "repeatable";
    auto* run = app.add_subcommand("run", "run a scenario and write its outputs");
    run->add_option("scenario", runFile, "scenario file (TOML)")->required();
    run->add_option("--out", outDir, "output directory (default: [output] directory of the scenario)");
    run->add_option("--threads", threads, "number of threads (default: all cores)")->check(CLI::NonNegativeNumber);
    run->add_flag("--quiet,-q", quiet, "no progress bar or summary");
    run->add_option("--resume", resumeDir,
                    "go on from the newest whole checkpoint of this run directory (the outputs go there too)");
    run->add_flag("--progress", progress, "show the progress line even when stderr is not a terminal");
    // One value per --set, so that the scenario may follow it.
    run->add_option("--set", sets, setHelp)
        ->expected(1)
        ->allow_extra_args(false)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);

    std::string checkFile;
    auto* check = app.add_subcommand("check", "validate a scenario and print what it would run");
    check->add_option("scenario", checkFile, "scenario file (TOML)")->required();
    check->add_option("--set", sets, setHelp)
        ->expected(1)
        ->allow_extra_args(false)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);

    std::string plotFile, plotOut, plotX = "time", plotTitle;
    std::vector<std::string> plotY;
    bool logX = false, logY = false;
    auto* plot = app.add_subcommand(
        "plot", "plot columns of a run's series.csv (or of any CSV file, such as a benchmark table) as a PNG");
    plot->add_option("source", plotFile, "run directory (its series.csv) or CSV file with a header row")->required();
    plot->add_option("-x,--x", plotX, "column on the x axis (default: time)");
    plot->add_option("-y,--y", plotY, "columns on the y axis (repeatable)")->required();
    plot->add_option("-o,--out", plotOut, "PNG file to write (default: COLUMN.png beside the CSV file)");
    plot->add_option("--title", plotTitle, "title (default: the file name)");
    plot->add_flag("--logx", logX, "logarithmic x axis");
    plot->add_flag("--logy", logY, "logarithmic y axis");

    std::string renderDir, renderOut, renderField, renderView, renderRange;
    int renderWidth = 0;
    double fps = 10;
    bool noMovie = false;
    auto* render = app.add_subcommand(
        "render", "draw every snapshot of a run as PNG, and an MP4 movie of them when ffmpeg is installed");
    render->add_option("rundir", renderDir, "run directory (what `haet run` wrote)")->required();
    render->add_option("--field", renderField,
                       "colour by this snapshot field: mode, material, velocity, velocity_z, force, radius, id, ... "
                       "(default: the run's [output] color_by)");
    render->add_option("--view", renderView, "3D: look along x, y, z, -x, -y, -z or DX,DY,DZ (default: the run's)");
    render->add_option("--range", renderRange, "colour bar limits LO,HI (default: the field's range over the run)");
    render->add_option("--width", renderWidth, "width of the view in px, 64 to 4096 (default: the run's)");
    render->add_option("--out", renderOut, "output directory (default: RUNDIR/render)");
    render->add_option("--fps", fps, "frames per second of movie.mp4 (default: 10)");
    render->add_flag("--no-movie", noMovie, "only the PNGs, even when ffmpeg is installed");

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = app.exit(e);
        return code == 0 ? 0 : 2;
    }

    try {
        if (*run) {
            const haet::Scenario sc = haet::loadScenario(runFile, sets);
            if (!resumeDir.empty() && !outDir.empty() &&
                std::filesystem::weakly_canonical(outDir) != std::filesystem::weakly_canonical(resumeDir)) {
                std::cerr << "error: --out " << outDir << " and --resume " << resumeDir
                          << ": a resumed run writes into the directory it resumes\n";
                return 2;
            }
            haet::RunOptions opt{outDir, threads, quiet,
                                 progress ? haet::ProgressDisplay::On
                                          : (quiet ? haet::ProgressDisplay::Off : haet::ProgressDisplay::Auto),
                                 resumeDir};
            opt.ranks = mpi.ranks();
            if (mpi.rank() != 0) {  // rank 0 reports for the run
                opt.quiet = true;
                opt.progress = haet::ProgressDisplay::Off;
            }
            return static_cast<int>(haet::runScenario(sc, opt, std::cerr));
        }
        if (*render) {
            haet::RenderOptions ro;
            ro.runDir = renderDir;
            ro.outDir = renderOut;
            if (!renderField.empty()) ro.field = renderField;
            if (!renderView.empty()) {
                ro.view = haet::parseView(renderView);
                if (!ro.view)
                    throw std::invalid_argument("--view " + renderView +
                                                ": expected x, y, z, -x, -y, -z or "
                                                "three numbers DX,DY,DZ, not all zero");
            }
            if (!renderRange.empty()) {
                ro.range = haet::parseRange(renderRange);
                if (!ro.range) throw std::invalid_argument("--range " + renderRange + ": expected LO,HI with HI > LO");
            }
            if (render->count("--width")) ro.widthPx = renderWidth;
            ro.fps = fps;
            ro.movie = !noMovie;
            haet::renderRun(ro, std::cerr);
            return 0;
        }
        if (*plot) {
            std::filesystem::path csv = plotFile;
            if (std::filesystem::is_directory(csv)) csv /= "series.csv";
            if (!std::filesystem::is_regular_file(csv))
                throw std::invalid_argument(csv.string() + ": no such file (a run directory holds series.csv)");
            const haet::CsvTable t = haet::readCsvTable(csv);
            auto col = [&](const std::string& name) {
                const int c = t.column(name);
                if (c < 0) {
                    std::string have;
                    for (const std::string& h : t.columns) have += (have.empty() ? "" : ", ") + h;
                    throw std::invalid_argument(csv.string() + ": no column '" + name + "'; it has " + have);
                }
                return t.values(c);
            };
            if (plotOut.empty()) plotOut = (csv.parent_path() / (plotY[0] + ".png")).string();
            const std::uint32_t colours[] = {0x1f77b4, 0xd62728, 0x2ca02c, 0xff7f0e, 0x9467bd, 0x8c564b};
            std::vector<haet::PlotSeries> series;
            const std::vector<double> x = col(plotX);
            for (std::size_t k = 0; k < plotY.size(); ++k)
                series.push_back({plotY[k], x, col(plotY[k]), colours[k % 6]});
            haet::LinePlotOptions o;
            o.logX = logX;
            o.logY = logY;
            o.markers = t.rows.size() <= 60;
            haet::writeLinePlotPng(plotOut, plotTitle.empty() ? csv.string() : plotTitle, plotX,
                                   plotY.size() == 1 ? plotY[0] : std::string(), series, o);
            return 0;
        }
        const haet::Scenario sc = haet::loadScenario(checkFile, sets);
        haet::describeScenario(sc, std::cout);
        for (const std::string& o : sc.overrides) std::cout << "set        " << o << "\n";
        std::cout << "ok\n";
        return 0;
    } catch (const haet::ScenarioError& e) {
        *thrown = true;
        std::cerr << "error: " << e.what() << "\n";
        return 2;
    } catch (const haet::CheckpointError& e) {  // --resume: corrupt, truncated, a later format, another scenario
        *thrown = true;
        std::cerr << "error: --resume: " << e.what() << "\n";
        return 2;
    } catch (const std::invalid_argument& e) {
        *thrown = true;
        std::cerr << "error: " << e.what() << "\n";
        return 2;
    } catch (const haet::IoError& e) {
        *thrown = true;
        std::cerr << "error: cannot write an output: " << e.what() << "\n";
        return static_cast<int>(haet::RunStatus::OutputFailed);
    } catch (const std::exception& e) {
        *thrown = true;
        std::cerr << "error: " << e.what() << "\n";
        return 1;
    }
}
