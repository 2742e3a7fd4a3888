// Secondary structure from backbone hydrogen bonds: DSSP (Kabsch & Sander 1983), as mkdssp 4
// computes it, reduced to the helix and strand a cartoon draws. Checked residue by residue against
// mkdssp itself (tests/data/test_molecule_cartoon.cpp).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "mfr/error.hpp"
#include "mfr/io/molecule.hpp"
#include "scene/point_grid.hpp"

namespace mfr {
namespace {

// DSSP's constants: q1·q2·f = 0.42·0.20·332 kcal·Å/mol (negative: the pairs' signs), the bond
// threshold, the floor for atoms too close, and the Cα distance beyond which no bond is tried.
constexpr double kCouplingConstant = -27.888;
constexpr double kMaxHBondEnergy = -0.5;
constexpr double kMinHBondEnergy = -9.9;
constexpr double kMinimalDistance = 0.5;
constexpr double kMinimalCADistance = 9.0;
constexpr double kMaxPeptideBondLength = 2.5;
// More Cα than this in one 9 Å cube is no protein (a folded chain holds about 6): refused rather
// than tried pair by pair.
constexpr std::size_t kMaxResiduesPerCell = 200;

struct Residue {
  glm::dvec3 n, ca, c, o, h;
  bool proline = false;
  std::size_t chainRun = 0;  // residues of one run share it; a break starts a new run
  // The two lowest-energy bonds this residue's N–H donates (DSSP's "acceptors" of a donor).
  std::array<std::int64_t, 2> acceptor{-1, -1};
  std::array<double, 2> acceptorEnergy{0.0, 0.0};
};

void keepBest(std::array<std::int64_t, 2>& who, std::array<double, 2>& energy, std::int64_t other, double e) {
  if (e < energy[0]) {
    who[1] = who[0];
    energy[1] = energy[0];
    who[0] = other;
    energy[0] = e;
  } else if (e < energy[1]) {
    who[1] = other;
    energy[1] = e;
  }
}

double hbondEnergy(const Residue& donor, const Residue& acceptor) {
  if (donor.proline) return 0.0;  // proline's N carries no hydrogen
  const double dHO = glm::distance(donor.h, acceptor.o), dHC = glm::distance(donor.h, acceptor.c),
               dNC = glm::distance(donor.n, acceptor.c), dNO = glm::distance(donor.n, acceptor.o);
  double e = kMinHBondEnergy;
  if (dHO >= kMinimalDistance && dHC >= kMinimalDistance && dNC >= kMinimalDistance && dNO >= kMinimalDistance)
    e = kCouplingConstant / dHO - kCouplingConstant / dHC + kCouplingConstant / dNC - kCouplingConstant / dNO;
  e = std::round(e * 1000.0) / 1000.0;  // mkdssp rounds as the original program printed
  return std::max(e, kMinHBondEnergy);
}

enum class Bridge : std::uint8_t { Parallel, Antiparallel };

struct Ladder {
  Bridge type;
  std::deque<std::int64_t> i, j;  // i ascending; j ascending too (antiparallel ones pushed in front)
};

}  // namespace

std::vector<SecondaryStructure> assignSecondaryStructure(const std::vector<BackboneResidue>& residues) {
  std::vector<SecondaryStructure> out(residues.size(), SecondaryStructure::Loop);
  // The residues that take part: complete backbones, in order; `index` maps back.
  std::vector<Residue> r;
  std::vector<std::size_t> index;
  for (std::size_t k = 0; k < residues.size(); ++k) {
    const BackboneResidue& b = residues[k];
    if (!b.n || !b.ca || !b.c || !b.o) continue;
    Residue x;
    x.n = *b.n;
    x.ca = *b.ca;
    x.c = *b.c;
    x.o = *b.o;
    x.h = x.n;
    x.proline = b.name == "PRO";
    const bool follows = !r.empty() && residues[index.back()].part == b.part &&
                         residues[index.back()].chain == b.chain &&
                         glm::distance(r.back().c, x.n) <= kMaxPeptideBondLength;
    x.chainRun = r.empty() ? 0 : (follows ? r.back().chainRun : r.back().chainRun + 1);
    if (follows && !x.proline) {
      const glm::dvec3 co = r.back().c - r.back().o;
      if (const double len = glm::length(co); len > 0.0) x.h = x.n + co / len;
    }
    r.push_back(x);
    index.push_back(k);
  }
  const auto count = static_cast<std::int64_t>(r.size());
  if (count < 2) return out;

  // Pairs whose Cα lie within 9 Å (mkdssp's "near" list): the only ones tried for hydrogen bonds
  // and for bridges. Each residue's later neighbours, ascending, so that everything below runs in
  // mkdssp's order (i, then j) — which decides ties between equal bond energies.
  std::vector<glm::dvec3> cas;
  cas.reserve(r.size());
  for (const Residue& x : r) cas.push_back(x.ca);
  const PointGrid grid(cas, kMinimalCADistance);
  if (grid.largestCell() > kMaxResiduesPerCell)
    throw Error("secondary structure",
                std::to_string(grid.largestCell()) + " residues in one cube of 9 Å: packed denser than any protein");
  std::vector<std::vector<std::int64_t>> near(r.size());
  for (std::int64_t i = 0; i < count; ++i) {
    std::vector<std::int64_t>& n = near[static_cast<std::size_t>(i)];
    grid.forEachWithin(r[static_cast<std::size_t>(i)].ca, kMinimalCADistance, [&](std::uint32_t j, double) {
      if (static_cast<std::int64_t>(j) > i) n.push_back(j);
    });
    std::sort(n.begin(), n.end());
  }
  for (std::int64_t i = 0; i < count; ++i)
    for (const std::int64_t j : near[static_cast<std::size_t>(i)]) {
      Residue &a = r[static_cast<std::size_t>(i)], &b = r[static_cast<std::size_t>(j)];
      keepBest(a.acceptor, a.acceptorEnergy, j, hbondEnergy(a, b));
      if (j != i + 1) keepBest(b.acceptor, b.acceptorEnergy, i, hbondEnergy(b, a));
    }
  // bond(d, a): the N–H of d bonds to the C=O of a (Kabsch & Sander's Hbond(a, d)).
  const auto bond = [&](std::int64_t d, std::int64_t a) {
    if (d < 0 || a < 0 || d >= count || a >= count) return false;
    const Residue& x = r[static_cast<std::size_t>(d)];
    for (int t = 0; t < 2; ++t)
      if (x.acceptor[static_cast<std::size_t>(t)] == a &&
          x.acceptorEnergy[static_cast<std::size_t>(t)] < kMaxHBondEnergy)
        return true;
    return false;
  };
  const auto unbroken = [&](std::int64_t from, std::int64_t to) {
    return from >= 0 && to < count && from <= to &&
           r[static_cast<std::size_t>(from)].chainRun == r[static_cast<std::size_t>(to)].chainRun;
  };
  // DSSP's classes as far as they decide helix and strand: 3₁₀ helices (G) and isolated bridges (B)
  // are drawn as loop but keep a π-helix off their residues, as in mkdssp.
  enum class Assigned : std::uint8_t { Loop, Alpha, Strand, Bridge, Helix310, Pi };
  std::vector<Assigned> ss(r.size(), Assigned::Loop);
  const auto at = [&](std::int64_t i) -> Assigned& { return ss[static_cast<std::size_t>(i)]; };

  // β-bridges over the near pairs, then ladders: consecutive bridges of one type. A ladder that
  // the next bridge (i + 1, j ± 1) would continue is found by that bridge's key.
  std::vector<Ladder> ladders;
  std::map<std::tuple<Bridge, std::int64_t, std::int64_t>, std::size_t> continuedBy;
  for (std::int64_t i = 1; i + 4 < count; ++i)
    for (const std::int64_t j : near[static_cast<std::size_t>(i)]) {
      if (j < i + 3 || j + 1 >= count) continue;
      if (!unbroken(i - 1, i + 1) || !unbroken(j - 1, j + 1)) continue;
      Bridge type;
      if ((bond(i + 1, j) && bond(j, i - 1)) || (bond(j + 1, i) && bond(i, j - 1)))
        type = Bridge::Parallel;
      else if ((bond(i + 1, j - 1) && bond(j + 1, i - 1)) || (bond(j, i) && bond(i, j)))
        type = Bridge::Antiparallel;
      else
        continue;
      const auto it = continuedBy.find({type, i, j});
      std::size_t l = ladders.size();
      if (it != continuedBy.end()) {
        l = it->second;
        continuedBy.erase(it);
        ladders[l].i.push_back(i);
        if (type == Bridge::Parallel)
          ladders[l].j.push_back(j);
        else
          ladders[l].j.push_front(j);
      } else {
        ladders.push_back({type, {i}, {j}});
      }
      continuedBy[{type, i + 1, type == Bridge::Parallel ? j + 1 : j - 1}] = l;
    }
  // Bulges: two ladders of one type whose strands are at most 1 (then 4 on the other strand) or
  // 2 residues apart become one. mkdssp compares unsigned differences: a negative one never links.
  // Ladders are in order of their first i, so the search for a's partners ends at the first b
  // that starts 6 or more after a ends.
  const auto within = [](std::int64_t d, std::int64_t limit) { return d >= 0 && d < limit; };
  std::vector<bool> merged(ladders.size(), false);
  for (std::size_t a = 0; a < ladders.size(); ++a) {
    if (merged[a]) continue;
    for (std::size_t b = a + 1; b < ladders.size(); ++b) {
      if (merged[b]) continue;
      Ladder &la = ladders[a], &lb = ladders[b];
      const std::int64_t ibi = la.i.front(), iei = la.i.back(), jbi = la.j.front(), jei = la.j.back();
      const std::int64_t ibj = lb.i.front(), iej = lb.i.back(), jbj = lb.j.front(), jej = lb.j.back();
      if (ibj - iei >= 6) break;
      if (la.type != lb.type || !unbroken(std::min(ibi, ibj), std::max(iei, iej)) ||
          !unbroken(std::min(jbi, jbj), std::max(jei, jej)) || !within(ibj - iei, 6) || (iei >= ibj && ibi <= iej))
        continue;
      const bool bulge = la.type == Bridge::Parallel
                             ? ((within(jbj - jei, 6) && within(ibj - iei, 3)) || within(jbj - jei, 3))
                             : ((within(jbi - jej, 6) && within(ibj - iei, 3)) || within(jbi - jej, 3));
      if (!bulge) continue;
      la.i.insert(la.i.end(), lb.i.begin(), lb.i.end());
      if (la.type == Bridge::Parallel)
        la.j.insert(la.j.end(), lb.j.begin(), lb.j.end());
      else
        la.j.insert(la.j.begin(), lb.j.begin(), lb.j.end());
      merged[b] = true;
    }
  }
  for (std::size_t l = 0; l < ladders.size(); ++l) {
    if (merged[l]) continue;
    const Ladder& ladder = ladders[l];
    const Assigned kind = ladder.i.size() > 1 ? Assigned::Strand : Assigned::Bridge;
    for (const auto& [from, to] :
         {std::pair{ladder.i.front(), ladder.i.back()}, std::pair{ladder.j.front(), ladder.j.back()}})
      for (std::int64_t k = from; k <= to; ++k)
        if (at(k) != Assigned::Strand) at(k) = kind;
  }

  // n-turns at i: the C=O of i bonds to the N–H of i + n, within one unbroken run. Helices from two
  // consecutive n-turns, in mkdssp's order: α (n = 4) over anything; 3₁₀ (n = 3) over loop only;
  // π (n = 5, which mkdssp 4 prefers to α) over loop, α and π only.
  const auto turn = [&](std::int64_t i, std::int64_t n) { return i >= 0 && unbroken(i, i + n) && bond(i + n, i); };
  for (std::int64_t i = 1; i + 4 < count; ++i)
    if (turn(i, 4) && turn(i - 1, 4))
      for (std::int64_t k = i; k <= i + 3; ++k) at(k) = Assigned::Alpha;
  for (std::int64_t i = 1; i + 3 < count; ++i)
    if (turn(i, 3) && turn(i - 1, 3)) {
      bool free = true;
      for (std::int64_t k = i; k <= i + 2; ++k) free = free && (at(k) == Assigned::Loop || at(k) == Assigned::Helix310);
      if (free)
        for (std::int64_t k = i; k <= i + 2; ++k) at(k) = Assigned::Helix310;
    }
  for (std::int64_t i = 1; i + 5 < count; ++i)
    if (turn(i, 5) && turn(i - 1, 5)) {
      bool free = true;
      for (std::int64_t k = i; k <= i + 4; ++k)
        free = free && (at(k) == Assigned::Loop || at(k) == Assigned::Alpha || at(k) == Assigned::Pi);
      if (free)
        for (std::int64_t k = i; k <= i + 4; ++k) at(k) = Assigned::Pi;
    }
  for (std::size_t k = 0; k < r.size(); ++k)
    out[index[k]] = ss[k] == Assigned::Alpha || ss[k] == Assigned::Pi ? SecondaryStructure::Helix
                    : ss[k] == Assigned::Strand                       ? SecondaryStructure::Strand
                                                                      : SecondaryStructure::Loop;
  return out;
}

}  // namespace mfr
