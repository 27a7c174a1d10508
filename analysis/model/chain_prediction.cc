#include "analysis/model/chain_prediction.h"

#include <cmath>
#include <stdexcept>

#include "analysis/model/torsional_chain.h"

namespace eol::analysis {
namespace {

struct Electrical {
  double r_ohm, l_h, t;
};

// The mode the torque excites most (largest Rp).
MotionalImpedance FittedMode(const Electrical& e, const RotorChainParams& rotor) {
  const ClampedMotor motor{e.r_ohm, e.l_h, e.t, BuildRotorChain(rotor)};
  MotionalImpedance best;
  for (const MotionalImpedance& m : motor.ModalTerms())
    if (std::isfinite(m.rp_ohm) && m.rp_ohm > best.rp_ohm) best = m;
  if (!(best.rp_ohm > 0.0))
    throw std::invalid_argument(
        "the motor's chain has no mode the torque excites (check "
        "transducer and rotor: every mode's Rp is 0)");
  return best;
}

MotionalImpedance WithSoft(const Electrical& e, RotorChainParams rotor, const std::string& defect) {
  std::string why;
  if (!SoftMagnetsForDefect(defect, rotor.magnets, &rotor.soft_magnets, &why))
    throw std::invalid_argument(why);
  return FittedMode(e, rotor);
}

// Every bond (good ones) keeps `kept` of its stiffness and damping.
MotionalImpedance Softened(const Electrical& e, RotorChainParams rotor, double kept) {
  rotor.soft_magnets.clear();
  rotor.bond.stiffness_nm_per_rad *= kept;
  rotor.bond.damping_nms_per_rad *= kept;
  return FittedMode(e, rotor);
}

// The loss (0-1) of every bond's stiffness that lowers the good mode by kDirectionF0Drop.
double LossForDrop(const Electrical& e, const RotorChainParams& rotor, double f_good) {
  const double target = f_good * (1.0 - kDirectionF0Drop);
  double lo = 0.0, hi = 1.0 - 1e-6;
  if (Softened(e, rotor, 1.0 - hi).f0_hz > target)
    throw std::invalid_argument(
        "softening every magnet bond never lowers the chain's mode by 1 %: the bonds do not "
        "carry the mode the test sees (check rotor.bond against bridge, shaft and fixture)");
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (Softened(e, rotor, 1.0 - mid).f0_hz > target ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

MotionalImpedance PredictGoodMode(double r_ohm, double l_h, double transmission_nm_per_a,
                                  const RotorChainParams& rotor) {
  std::string why;
  if (!rotor.IsValid(&why)) throw std::invalid_argument("rotor: " + why);
  RotorChainParams good = rotor;
  good.soft_magnets.clear();
  return FittedMode(Electrical{r_ohm, l_h, transmission_nm_per_a}, good);
}

ChainPrediction PredictChain(double r_ohm, double l_h, double transmission_nm_per_a,
                             const RotorChainParams& rotor) {
  std::string why;
  if (!rotor.IsValid(&why)) throw std::invalid_argument("rotor: " + why);
  const Electrical e{r_ohm, l_h, transmission_nm_per_a};
  ChainPrediction p;
  RotorChainParams good = rotor;
  good.soft_magnets.clear();
  p.good = FittedMode(e, good);
  p.half_soft = WithSoft(e, good, "partial:0.5");
  p.all_soft = WithSoft(e, good, "all_soft");
  p.direction_loss = LossForDrop(e, good, p.good.f0_hz);
  const MotionalImpedance soft = Softened(e, good, 1.0 - p.direction_loss);
  p.residue_to_f0 = std::log(soft.ResidueOhmPerS() / p.good.ResidueOhmPerS()) /
                    -std::log(soft.f0_hz / p.good.f0_hz);
  p.total_inertia_kg_m2 = rotor.magnets * (rotor.magnet_inertia_kg_m2 + rotor.pole_inertia_kg_m2) +
                          rotor.hub_inertia_kg_m2;
  return p;
}

}  // namespace eol::analysis
