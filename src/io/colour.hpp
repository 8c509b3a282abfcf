#pragma once
// Colours of the pictures: a continuous map for values (a colour bar) and a palette for categories (a legend).
// Colours are 0xRRGGBB.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace haet {

/// Viridis (van der Walt & Smith, matplotlib 2015), sampled at 9 points and interpolated linearly: dark blue at 0,
/// yellow at 1; perceptually ordered and legible when printed in grey.
inline std::uint32_t viridis(double t) {
    static constexpr std::array<std::array<double, 3>, 9> k = {{{68, 1, 84},
                                                                {71, 45, 123},
                                                                {59, 82, 139},
                                                                {44, 114, 142},
                                                                {33, 145, 140},
                                                                {40, 174, 128},
                                                                {94, 201, 98},
                                                                {173, 220, 48},
                                                                {253, 231, 37}}};
    t = std::isfinite(t) ? std::clamp(t, 0.0, 1.0) : 0.0;
    const double s = t * (k.size() - 1);
    const std::size_t i = std::min<std::size_t>(static_cast<std::size_t>(s), k.size() - 2);
    const double f = s - static_cast<double>(i);
    std::uint32_t rgb = 0;
    for (int c = 0; c < 3; ++c)
        rgb = (rgb << 8) | static_cast<std::uint32_t>(std::lround(k[i][c] + f * (k[i + 1][c] - k[i][c])));
    return rgb;
}

/// The colour of a value missing from the data (NaN).
inline constexpr std::uint32_t kNoValueColour = 0xbdbdbd;

/// The map of values in [lo, hi] onto viridis; values outside take the end colours.
struct ColourBar {
    double lo = 0, hi = 1;

    std::uint32_t rgb(double v) const {
        if (!std::isfinite(v)) return kNoValueColour;
        return viridis(hi > lo ? (v - lo) / (hi - lo) : 0.5);
    }
};

/// Category k of a legend (Tableau 10, cycled).
inline std::uint32_t categoryColour(std::size_t k) {
    static constexpr std::uint32_t palette[] = {0x1f77b4, 0xff7f0e, 0x2ca02c, 0xd62728, 0x9467bd,
                                                0x8c564b, 0xe377c2, 0x7f7f7f, 0xbcbd22, 0x17becf};
    return palette[k % 10];
}

/// What the colours of a picture mean, drawn in a strip at its right: a legend of categories, or a colour bar.
struct PictureKey {
    struct Entry {
        std::string label;
        std::uint32_t rgb = 0;
    };
    std::string title;              ///< what is coloured ("mode", "velocity [m/s]"); empty: no key
    std::vector<Entry> categories;  ///< a legend when not empty
    ColourBar bar;                  ///< otherwise a colour bar over [bar.lo, bar.hi]
    bool empty() const { return title.empty(); }
};

}  // namespace haet
