#!/usr/bin/env sh
# Damped oscillator: symbolic zeta gives the under-, critically and over-damped cases with their
# conditions; numbers pick the right one.
pdyn dsolve "x'' + 2*zeta*wn*x' + wn^2*x = 0" --ic "x(0)=x0, x'(0)=v0"
for z in 0.1 1 2; do
  pdyn dsolve "x'' + 2*zeta*wn*x' + wn^2*x = 0" --ic "x(0)=1, x'(0)=0" --set "zeta=$z,wn=3"
done
# Resonance: the response grows like t.
pdyn dsolve "x'' + 4*x = sin(2*t)" --ic "x(0)=0, x'(0)=0"
