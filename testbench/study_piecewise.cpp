// study_piecewise: how far a piecewise polynomial brings the specular lobe's error down, against
// what it costs (docs/specular-unit.md, "Segments"). For each n, degree d and segment count S the
// least whole-lobe maximum error |f - c^n| over c in [0, 1] (approx/piecewise.h: minimax per
// segment, the segments and the cut-off laid for equal error), beside the paper's clamped
// quadratic (its inflection fit and the minimax coefficient) as the device has them. Cost per n,
// stated as a model: S breakpoints (uQ1.15, 16 bits) and S (d+1) coefficients (18 bits each); d
// multipliers for Horner's scheme, S comparators to pick the segment.
//   study_piecewise [n ...]      (default 8 32 100 300 1000)
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "approx/fit.h"
#include "approx/lobe_error.h"
#include "approx/piecewise.h"

int main(int argc, char** argv) {
  std::vector<double> ns;
  for (int i = 1; i < argc; ++i) ns.push_back(std::atof(argv[i]));
  if (ns.empty()) ns = {8, 32, 100, 300, 1000};
  std::printf("%-26s %7s %7s %11s", "approximation", "bits/n", "mults", "comparators");
  for (double n : ns) std::printf(" %9s", ("n=" + std::to_string(static_cast<int>(n))).c_str());
  std::printf("\n");
  for (shd::FitKind fit : {shd::FitKind::Inflection, shd::FitKind::Minimax}) {
    std::printf("%-26s %7d %7d %11d", (std::string("paper quadratic, ") + shd::toString(fit)).c_str(), 18, 2, 0);
    for (double n : ns) std::printf(" %9.5f", shd::summarizeError(shd::fitApprox(fit, 2, n), n).at("lobe").max_abs);
    std::printf("\n");
  }
  for (int d : {1, 2})
    for (int S : {1, 2, 4, 8}) {
      std::printf("%-26s %7d %7d %11d", ("degree " + std::to_string(d) + ", " + std::to_string(S) + " segment(s)").c_str(),
                  S * (16 + 18 * (d + 1)), d, S);
      for (double n : ns) std::printf(" %9.5f", shd::fitPiecewise(n, S, d).err);
      std::printf("\n");
    }
  return 0;
}
