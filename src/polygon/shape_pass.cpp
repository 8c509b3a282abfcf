// The force pass of scenes with polygons: the pair pass over the polygon kernel (polygon/polygon_kernel.hpp),
// instantiated per (disk normal law, tangential law, polygon law), behind the engine's ShapePass interface.
#include "tdm/shape_pass.hpp"

#include <memory>

#include "polygon/polygon_kernel.hpp"
#include "tdm/pair_pass.hpp"

namespace haet {
namespace {

template <class Normal, class Tangential, class Law>
class PolygonPass final : public ShapePass {
public:
    ForceStats forces(const ForceContext<2>& ctx) override {
        polygon::rotateShapes(ctx.p, ps_);
        const polygon::PolygonKernel<Normal, Tangential, Law> kernel(ctx, ps_);
        auto none = [](std::size_t, const Vec<2>&, const Ang<2>&) {};
        return runPairPass(ctx, kernel, ps_.pass, none);
    }
    double energy(const ForceContext<2>& ctx) override {
        return contactEnergy(ctx, polygon::PolygonKernel<Normal, Tangential, Law>(ctx, ps_));
    }

private:
    polygon::PolygonScratch ps_;
};

template <class Normal, class Tangential>
std::unique_ptr<ShapePass> withPolygonLaw(const ContactSetup& cs) {
    const bool potential = !cs.polygonTable.empty() && cs.polygonTable[0].law == PolygonLaw::Potential;
    if (potential) return std::make_unique<PolygonPass<Normal, Tangential, polygon::PotentialLaw>>();
    return std::make_unique<PolygonPass<Normal, Tangential, polygon::OverlapAreaLaw>>();
}

template <class Normal>
std::unique_ptr<ShapePass> withTangential(const ContactSetup& cs) {
    if (cs.tangential == TangentialLaw::Spring) return withPolygonLaw<Normal, SpringTangential>(cs);
    return withPolygonLaw<Normal, NoTangential>(cs);
}

}  // namespace

std::unique_ptr<ShapePass> makeShapePass(const ContactSetup& cs) {
    if (cs.normal == NormalLaw::Linear) return withTangential<LinearNormal>(cs);
    if (cs.hertzDamping == HertzDamping::Tsuji) return withTangential<HertzTsujiNormal>(cs);
    return withTangential<HertzViscoNormal>(cs);  // A* = 0 is the undamped Hertz law
}

}  // namespace haet
