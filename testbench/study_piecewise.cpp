// study_piecewise: how far a piecewise polynomial brings the specular lobe's error down, against
// what it costs (docs/specular-unit.md, "Segments"). For each n, degree d and segment count S the
// least whole-lobe maximum error |f - c^n| over c in [0, 1] (approx/piecewise.h: minimax per
// segment, the segments and the cut-off laid for equal error), beside the paper's clamped
// quadratic (its inflection fit and the minimax coefficient) as the device has them. Cost per n,
// stated as a model: S breakpoints (uQ1.15, 16 bits) and S (d+1) coefficients (18 bits each); d
// multipliers for Horner's scheme, S comparators to pick the segment. Then the same segments in
// integers (approx/piecewise.h PiecewiseCodes) for coefficient fraction bits Kf = 16..24.
//   study_piecewise [n ...]      (default 8 32 100 300 1000)
#include <algorithm>
#include <cmath>
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
  // The same segments as a unit would hold them (approx/piecewise.h PiecewiseCodes): cosine
  // uQ1.15, f uQ1.16, coefficients with Kf fraction bits; the largest |f - c^n| over every cosine
  // code in LSBs of f, beside the ideal segments' error in the same unit, and the integer bits the
  // coefficients need.
  const int wc = 15, wf = 16;
  std::printf("\nquantised (cos uQ1.%d, f uQ1.%d): max |f - c^n| in f-LSB over every cos code; int = coefficient integer bits\n",
              wc, wf);
  for (int S : {2, 4}) {
    const int d = 2;
    std::vector<shd::PiecewiseFit> fits;
    for (double n : ns) fits.push_back(shd::fitPiecewise(n, S, d));
    std::printf("%-26s", ("degree 2, " + std::to_string(S) + " segments, ideal").c_str());
    for (const shd::PiecewiseFit& f : fits) std::printf(" %9.2f", std::ldexp(f.err, wf));
    std::printf("\n");
    for (int kf : {16, 18, 20, 24}) {
      std::printf("%-26s", ("  Kf = " + std::to_string(kf)).c_str());
      int ibits = 0;
      for (size_t i = 0; i < ns.size(); ++i) {
        const shd::PiecewiseCodes q = shd::quantisePiecewise(fits[i], wc, wf, kf);
        double worst = 0;
        for (int64_t C = 0; C <= (int64_t{1} << wc); ++C)
          worst = std::max(worst, std::fabs(static_cast<double>(q.eval(C)) - std::ldexp(std::pow(std::ldexp(static_cast<double>(C), -wc), ns[i]), wf)));
        ibits = std::max(ibits, q.coefIntBits());
        std::printf(" %9.2f", worst);
      }
      std::printf("   int %d\n", ibits);
    }
  }
  return 0;
}
