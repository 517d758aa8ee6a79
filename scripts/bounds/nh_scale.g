# nh_scale.g: the error of phong-fixed's N.H (a Q2.32 code, model/render/normalize.h
# scaleCosine) against the exact cosine of the normalised normal and the unit half vector,
# proved by Gappa. scripts/bounds.py fills in the named fields.
#
# The datapath: h is the half vector as the renderer normalises it in double (|h| <= 1 + 2^-40),
# H its components rounded to Q1.30 (each within 2^-31, so |H - h| <= sqrt(3) 2^-31); d = N . H
# is an exact integer dot product; the scaled cosine is d r 2^-s rounded half up to 32 fraction
# bits, which equals round(Dn rho) with Dn = (N / |N|) . H, |Dn| <= |H|, and rho - 1 in
# [%(rlo)s, %(rhi)s] (rsqrt_newton.g). The exact cosine is (N / |N|) . h = Dn - he with
# he = (N / |N|) . (H - h), |he| <= |H - h| (Cauchy-Schwarz).
C = fixed<-32,%(rnd)s>(Dn * rho);

{ Dn in [-%(dmax)s, %(dmax)s] /\ rho - 1 in [%(rlo)s, %(rhi)s] /\ he in [-%(hmax)s, %(hmax)s]
  -> C - (Dn - he) in ? }

C - (Dn - he) -> (C - Dn * rho) + Dn * (rho - 1) + he;
