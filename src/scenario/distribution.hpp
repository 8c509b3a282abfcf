#pragma once
// Particle size distributions of [[insert]] and [[inlet]] blocks (docs/scenario.md, "Size distributions"): uniform
// in a radius range, a table of discrete sizes with number or mass fractions (a sieve analysis), and normal and
// log-normal distributions truncated to a range. Radii, not diameters, as everywhere in a scenario; `haet check`
// prints diameters (mean and d50, by number and by mass), as a particle-size analysis reports them.
#include <cstddef>
#include <string>
#include <vector>

#include "core/rng.hpp"

namespace haet {

enum class SizeKind { Uniform, Discrete, LogNormal, Normal };

/// A radius distribution by number: the probability that a particle drawn has a radius <= r is cdf(r).
struct SizeDistribution {
    SizeKind kind = SizeKind::Uniform;
    double min = 0, max = 0;    ///< radius range [m]: the uniform bounds, the truncation range, or a table's extremes
    double location = 0;        ///< normal: mean radius before truncation [m]; log-normal: median radius [m]
    double sigma = 0;           ///< normal: standard deviation of r [m]; log-normal: of ln r [-]
    std::vector<double> radii;  ///< discrete: the sizes, ascending [m]
    std::vector<double> numberFraction;  ///< discrete: probability by number of each size [-], sums to 1
    std::vector<double> massFraction;    ///< discrete: share of the mass of each size [-], sums to 1

    /// One radius [m]. Uniform draws rng.uniform(min, max), the draw inserts made before distributions existed;
    /// the others one uniform number each, through the inverse of cdf (truncated: u in [cdf(min), cdf(max)]).
    double sample(Rng& rng) const;
    /// Probability by number that a radius is <= r [-].
    double cdf(double r) const;
};

/// A uniform distribution in [min, max] (min = max: one size).
SizeDistribution uniformSizes(double min, double max);
/// Discrete sizes from fractions by number (byMass = false) or by mass, mass proportional to r^dimension (the
/// volume of the sphere, the area of the disk; polygons of one kind share the factor of their shape).
SizeDistribution discreteSizes(std::vector<double> radii, const std::vector<double>& fractions, bool byMass,
                               int dimension);
SizeDistribution normalSizes(double mean, double sigma, double min, double max);
SizeDistribution logNormalSizes(double median, double sigma, double min, double max);

/// Diameters that describe a distribution [m]: means and medians (d50) by number and by mass (mass ~ r^dimension).
struct SizeSummary {
    double meanByNumber = 0, meanByMass = 0;
    double d50ByNumber = 0, d50ByMass = 0;
};
SizeSummary summarize(const SizeDistribution& s, int dimension);

/// One line for `haet check`: the kind and its parameters.
std::string describeSizes(const SizeDistribution& s);

}  // namespace haet
