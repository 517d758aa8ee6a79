# span_plane.g: the error of the span unit's attribute values against the exact plane, proved by
# Gappa for every pixel of a W x H viewport. scripts/bounds.py fills in the named fields.
# Configuration %(config)s: AttrBits %(AttrBits)s, viewport %(W)s x %(H)s.
#
# Setup rounds three exact rationals half to even to integer codes (model/raster/setup.cpp): the
# plane at the reference pixel, I0 -> iref, and the gradients gx -> didx, gy -> didy. The unit
# then produces, at a pixel X columns and Y rows from the reference, exactly
#   iref + didx X + didy Y   (mod 2^AttrBits; exact where the value fits, which setup checks):
# whatever the lane mode, its steps by didx (or LanesPerTri didx), its rows by didy, its jumps
# and its reflected walk are integer additions of these three codes, so nothing accumulates
# (docs/proved-bounds.md gives the induction). The reference pixel is the triangle's top-left
# pixel clamped into the viewport, so 0 <= X <= W - 1 and 0 <= Y <= H - 1 at every covered pixel.
iref = int<ne>(I0);
didx = int<ne>(gx);
didy = int<ne>(gy);
value = iref + didx * X + didy * Y;   # the unit: exact integer arithmetic
plane = I0 + gx * X + gy * Y;         # the exact plane

{ I0 in [-%(lim)s, %(lim)s] /\ gx in [-%(lim)s, %(lim)s] /\ gy in [-%(lim)s, %(lim)s]
  /\ @FIX(X, 0) /\ X in [0, %(Xmax)s] /\ @FIX(Y, 0) /\ Y in [0, %(Ymax)s]
  -> value - plane in ? }

value - plane -> (iref - I0) + (didx - gx) * X + (didy - gy) * Y;
