# rsqrt_newton.g: the relative error of phong-fixed's reciprocal square root (rsqrtCore<10>,
# model/render/normalize.h), proved by Gappa. scripts/bounds.py fills in the named fields.
#
# v > 0 is normalised to m = v 4^shift in [2^60, 2^62) (v >> 2 when v >= 2^62); mu = v 4^shift
# 2^-62 in [1/4, 1) is the exact value whose 1/sqrt is wanted, muq = mq 2^-32 its truncation
# (mq = m >> 30). The seed r0 (uQ2.16) comes from a table of %(entries)s entries indexed by muq;
# scripts/bounds.py computes, exactly over every entry and every muq of its interval, the range
# of t0 - 1 = muq r0^2 - 1: [%(elo)s, %(ehi)s]. One Newton step in integers:
#   mr = floor(mq r0^2 / 2^32)               (Q32)  mr = dn(muq r0^2) at 2^-32
#   r1 = floor(r0 (3 2^32 - mr) / 2^17)      (Q32)  r1 = dn(r0 (3 - mr) / 2) at 2^-32
# rho = r1 sqrt(mu) is the relative accuracy (1 means exact); this proves the range of
# E = r1^2 mu - 1 = rho^2 - 1, and scripts/bounds.py takes rho - 1 = E / (1 + sqrt(1 + E)).
muq = fixed<-32,dn>(mu);
r0  = fixed<-16,dn>(r0x);
t0  = muq * r0 * r0;
mr  = fixed<-32,dn>(t0);
r1p = r0 * (3 - mr) / 2;
r1  = fixed<-32,dn>(r1p);
r1e = r0 * (3 - t0) / 2;          # the exact Newton step from the seed
E   = r1 * r1 * mu - 1;

{ mu in [1b-2, 1] /\ r0x in [%(r0min)s, %(r0max)s] /\ t0 - 1 in [%(elo)s, %(ehi)s] -> E in ? }

# r1e^2 muq = t0 (3 - t0)^2 / 4, so r1e^2 muq - 1 = (t0 - 1)^2 (t0 - 4) / 4: the step squares
# the seed's error. The rest: the two truncations and muq against mu.
E -> (r1e * r1e * muq - 1) + (r1 - r1e) * (r1 + r1e) * mu + r1e * r1e * (mu - muq);
r1e * r1e * muq - 1 -> (t0 - 1) * (t0 - 1) * (t0 - 4) / 4;
r1 - r1e -> (r1 - r1p) + r0 * (t0 - mr) / 2;
