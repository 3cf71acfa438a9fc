#!/usr/bin/env sh
# Straight-line motion rules (3.1.3): acceleration given as a function of time, speed or position.
pdyn dsolve --rule "a(v) = -g - c*v^2" --ic "x(0)=0, v(0)=v0"        # closed form (atan, log)
pdyn dsolve --rule "a(t) = exp(-t^2)" --at 1,2                        # quadrature with error estimate
pdyn dsolve --rule "a(x) = -k*x" --ic "x(0)=0, v(0)=v0" --set k=4,v0=2 --at 0.5
pdyn dsolve "x'' + sin(x) = 0" --ic "x(0)=1, x'(0)=0" || true        # refused: use pdyn run
