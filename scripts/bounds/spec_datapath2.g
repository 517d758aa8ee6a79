# spec_datapath2.g: the rounding error of the degree-2 specular unit before its clamp, proved by
# Gappa for every cos code and every coefficient code in the PROM's range at once.
# scripts/bounds.py fills in the named fields from the configuration and the PROM table.
# Configuration %(config)s: cos uQ1.%(Wc)s, coefficient uQ%(Ci)s.%(Cf)s, c^2 - c to %(Df)s
# fraction bits, f to %(Wf)s fraction bits (model/device/spec_unit.cpp, rtl/shd_spec_unit.v).
#
# The unit: c = min(cos_i, 1.0); dt = floor(c^2 - c) to Df bits; P = a dt (MUL2, exact);
# Pr = P rounded half up (nu: to nearest, ties toward +infinity) to Wf bits; f = clamp(c + Pr).
# The ideal device on the same stored a: clamp(c + a (c^2 - c)). Both add the same exact c,
# so the error before the clamp is Pr - a (c^2 - c); scripts/bounds.py carries it through the
# clamp (spec_output.g).
c  = fixed<-%(Wc)s,dn>(cx);     # a cos code: uQ1.Wc, so c lies on the 2^-Wc grid
a  = fixed<-%(Cf)s,dn>(ax);     # a coefficient code: on the 2^-Cf grid
d  = c * c - c;                 # MUL1, inverter, Sm1 with carry-in: exact
dt = fixed<-%(Df)s,dn>(d);      # truncation (floor) to Df fraction bits
P  = a * dt;                    # MUL2: exact
Pr = fixed<-%(Wf)s,%(rnd)s>(P); # round half up to Wf fraction bits

{ cx in [0, 1] /\ ax in [%(amin)s, %(amax)s] -> Pr - a * d in ? }

d -> (c - 1b-1) * (c - 1b-1) - 1b-2;   # c^2 - c = (c - 1/2)^2 - 1/4 >= -1/4
