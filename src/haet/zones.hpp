#pragma once
// Zone labels of the hybrid (docs/physics.md A.2): a uniform grid over the box; each zone is dense (time-driven) or
// dilute (event-driven) from its smoothed local volume fraction, with hysteresis, sticky zones (enduring
// contacts, particles resting on walls) and a buffer of dense-adjacent zones.
#include <array>
#include <cstdint>
#include <vector>

#include "core/particles.hpp"
#include "geometry/domain.hpp"
#include "io/checkpoint.hpp"
#include "neighbor/cell_grid.hpp"

namespace haet {

struct ZoneSettings {
    double size = 0;       ///< zone edge [m] (rounded so that an integer number of zones spans each axis)
    double phiOn = 0.3;    ///< dilute -> dense above this smoothed fraction [-]
    double phiOff = 0.25;  ///< dense -> dilute below this one [-]
    int buffer = 1;        ///< zones around a dense zone whose particles are time-driven too
};

template <int D>
class ZoneGrid {
public:
    ZoneGrid(const Domain<D>& dom, const ZoneSettings& s);

    int count() const { return grid_.count(); }
    const std::array<int, D>& dims() const { return grid_.dims(); }
    /// The zones as cells (zone index = cell index).
    const CellGrid<D>& grid() const { return grid_; }
    /// The zone of x; beyond a periodic face x is wrapped into the box, beyond an open one it falls into the
    /// outer zones.
    int zoneOf(const Vec<D>& x) const { return grid_.wrappedCellOf(x); }

    /// Recomputes the volume fraction of every zone from the particles (centres in the zone), smooths it over
    /// the zone and its neighbours, and updates the labels with hysteresis. sticky[z] != 0 keeps zone z dense.
    void relabel(const Particles<D>& p, const std::vector<std::uint8_t>& sticky);
    /// The same from the particle volume per zone [m^D] (size count()), when the caller keeps it current.
    void relabel(const std::vector<double>& volume, const std::vector<std::uint8_t>& sticky);
    /// Index stride of axis k: zone index = sum of coordinate k * stride(k).
    int stride(int k) const { return grid_.stride(k); }

    /// Dense zone (before the buffer).
    bool dense(int z) const { return dense_[z]; }
    /// A particle in zone z is time-driven: z or a zone within `buffer` of it is dense.
    bool timeDriven(int z) const { return tdm_[z]; }
    double fraction(int z) const { return phi_[z]; }        ///< raw fraction of zone z
    double smoothed(int z) const { return phiSmooth_[z]; }  ///< smoothed fraction of zone z
    std::size_t changedLast() const { return changed_; }  ///< zones whose timeDriven label changed in the last relabel
    double zoneVolume() const { return cellVolume_; }
    Vec<D> zoneWidth() const { return grid_.width(); }
    Vec<D> origin() const { return grid_.origin(); }

    /// The labels and fractions of the last relabel, which the next one's hysteresis and the steps between read
    /// (haet/state.cpp); loadState throws CheckpointError (Corrupt) for another number of zones.
    void saveState(ByteWriter& out) const;
    void loadState(ByteReader& in);

private:
    /// out[z] = op over the zones within `radius` of z along axis k (periodic axes wrap, each zone once; open
    /// axes are clipped): one pass of a box filter that is separable over the axes.
    template <class T, class Op>
    void alongAxis(int k, int radius, const std::vector<T>& in, std::vector<T>& out, Op op) const;

    ZoneSettings s_;
    CellGrid<D> grid_;
    double cellVolume_ = 1;
    std::vector<double> phi_, phiSmooth_;
    std::vector<std::uint8_t> dense_, tdm_;
    std::vector<double> invCount_;               // 1 / zones in each zone's smoothing block
    std::vector<double> sum_;                    // scratch of relabel: the smoothing's sums
    std::vector<std::uint8_t> mark_, markNext_;  // and the buffer's dilation
    std::size_t changed_ = 0;
};

}  // namespace haet
