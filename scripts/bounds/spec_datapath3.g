# spec_datapath3.g: the rounding error of the degree-3 specular unit before its clamp, proved by
# Gappa for one PROM entry (u, v, cut) and every cos code from the cut to 1.0 (below the cut the
# unit and the ideal device both give 0). scripts/bounds.py fills in the named fields.
# Configuration %(config)s, n = %(n)s: cos uQ1.%(Wc)s, coefficients sQ%(Ci)s.%(Cf)s, c^2 - c to
# %(Df)s fraction bits, the Horner term to %(Hf)s, f to %(Wf)s (model/device/spec_unit.cpp).
#
# The unit: dt = floor(c^2 - c) to Df bits; gt = floor(u c + v) to Hf bits; P = dt gt (MUL2,
# exact); Pr = P rounded half up to Wf bits; f = clamp(c + Pr). The ideal device on the same
# stored u, v: clamp(c + (c^2 - c)(u c + v)); the error before the clamp is Pr - d g.
c  = fixed<-%(Wc)s,dn>(cx);     # a cos code
u  = %(U)sb-%(Cf)s;             # a1, stored
v  = %(V)sb-%(Cf)s;             # a1 + b1, stored
d  = c * c - c;                 # exact
dt = fixed<-%(Df)s,dn>(d);      # truncation to Df fraction bits
g  = u * c + v;                 # Horner, exact
gt = fixed<-%(Hf)s,dn>(g);      # truncation to Hf fraction bits
P  = dt * gt;                   # MUL2: exact
Pr = fixed<-%(Wf)s,%(rnd)s>(P); # round half up to Wf fraction bits

{ cx in [%(cut)sb-%(Wc)s, 1] -> Pr - d * g in ? }

d -> (c - 1b-1) * (c - 1b-1) - 1b-2;
