// Reference specular lobes in double precision: the exact functions that the paper's
// polynomial approximations (approx/fit.h) and the hardware specular unit are measured against.
//
// Conventions: every dot product is a cosine in [-1, 1] of unit vectors; a lobe is 0 for a
// back-facing cosine (<= 0). n is the Phong/Blinn shininess exponent (n >= 0).
#pragma once

#include "scene/vec.h"  // kPi

namespace shd {

// Phong: max(0, R.V)^n.
double phongLobe(double r_dot_v, double n);

// Blinn-Phong: max(0, N.H)^n. This is the cos^n that approx/fit.h approximates (c = N.H).
double blinnLobe(double n_dot_h, double n);

// Energy-normalised Blinn-Phong distribution D(h) = (n+2)/(2 pi) * max(0, N.H)^n, normalised so
// that the projected microfacet area is one: integral over the hemisphere of D(h) (N.H) dw = 1.
double normalizedBlinn(double n_dot_h, double n);

// Schlick's rational replacement of cos^n [Schlick 1994]: c / (n - n c + c) for c in (0, 1],
// 0 for c <= 0; c > 1 is treated as 1. Needs one division, no pow. Equals 1 at c = 1 and is
// increasing in c for n > 0.
double schlickLobe(double c, double n);

// Cook-Torrance, the physically based reference [Cook & Torrance 1982]:
//   f = F * D * G / (pi * (N.L) * (N.V))
//   D  Beckmann in the 1982 form: exp(-tan^2(a) / m^2) / (m^2 cos^4(a)), a = angle(N, H)
//      (this D has no 1/pi: together with the pi in the denominator above it is the paper's
//      formula; the pi-normalised Beckmann D is beckmannD below);
//   F  Schlick's Fresnel approximation f0 + (1 - f0)(1 - V.H)^5;
//   G  min(1, 2 (N.H)(N.V) / (V.H), 2 (N.H)(N.L) / (V.H)).
// Returns 0 when N.L <= 0 or N.V <= 0 (light or viewer below the surface) and when N.H <= 0
// or V.H <= 0 (no microfacet can reflect L into V). Symmetric in (N.L, N.V) (reciprocity):
// V.H = L.H for the half vector, so F and G do not change when L and V are swapped.
struct CookTorranceParams {
  double roughness_m = 0.3;  // Beckmann RMS slope m > 0
  double f0 = 0.04;          // Fresnel reflectance at normal incidence, in [0, 1]
};
double cookTorrance(double n_dot_l, double n_dot_v, double n_dot_h, double v_dot_h,
                    CookTorranceParams p);

// pi-normalised Beckmann distribution exp(-tan^2(a)/m^2) / (pi m^2 cos^4(a)); its projected
// area integral (over the hemisphere of D(h) (N.H) dw) is 1. 0 for N.H <= 0.
double beckmannD(double n_dot_h, double m);

// The usual correspondence between Blinn-Phong shininess and Beckmann roughness:
// m = sqrt(2 / (n + 2)). Derivation: near the peak, for small angles a, cos^n(a) ~ exp(-n a^2/2)
// and the Beckmann exponent -tan^2(a)/m^2 ~ -a^2/m^2; the normalised lobes (n+2)/(2 pi) cos^n
// and 1/(pi m^2) exp(-a^2/m^2) then agree to first order when m^2 = 2/(n+2) (also the peak
// heights (n+2)/(2 pi) = 1/(pi m^2) match exactly) [Walter et al. 2007, eq. 30].
double beckmannRoughnessForBlinn(double n);

}  // namespace shd
