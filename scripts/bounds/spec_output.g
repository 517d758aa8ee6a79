# spec_output.g: the datapath error at the colour outputs (MUL3..MUL5), proved by Gappa from the
# error of f (spec_datapath2.g or spec_datapath3.g, carried through the clamp by
# scripts/bounds.py), for every light code L. Configuration %(config)s: f uQ1.%(Wf)s, light and
# colour unorm%(Lbits)s.
#
# f is the unit's spec_o (on the 2^-Wf grid), fs the ideal device's value; both lie in [0, 1]
# and f - fs lies in [%(flo)s, %(fhi)s]. out = round half up (f L), the ideal colour fs L.
f   = fixed<-%(Wf)s,dn>(fx);
out = int<%(rnd)s>(f * L);

{ fx in [0, 1] /\ fs in [0, 1] /\ f - fs in [%(flo)s, %(fhi)s] /\ @FIX(L, 0) /\ L in [0, %(Lmax)s]
  -> out - fs * L in ? }

out - fs * L -> (out - f * L) + (f - fs) * L;
