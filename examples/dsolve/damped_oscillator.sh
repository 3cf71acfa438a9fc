#!/usr/bin/env sh
# Damped oscillator: symbolic zeta gives the under-, critically and over-damped cases with their
# conditions; numbers pick the right one.
pdyn dsolve "x'' + 2*zeta*wn*x' + wn^2*x = 0" --ic "x(0)=x0, x'(0)=v0"
pdyn dsolve "x'' + 2*zeta*wn*x' + wn^2*x = 0" --ic "x(0)=1, x'(0)=0" --set "zeta=0.1,wn=3"
pdyn dsolve "x'' + 2*zeta*wn*x' + wn^2*x = 0" --ic "x(0)=1, x'(0)=0" --set "zeta=1,wn=3"
pdyn dsolve "x'' + 2*zeta*wn*x' + wn^2*x = 0" --ic "x(0)=1, x'(0)=0" --set "zeta=2,wn=3"
# Resonance: the response grows like t.
pdyn dsolve "x'' + 4*x = sin(2*t)" --ic "x(0)=0, x'(0)=0"
