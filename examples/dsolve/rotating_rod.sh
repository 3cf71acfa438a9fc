#!/usr/bin/env sh
# Rotating rod pushing a block with friction:
# r(t) = V exp(-mu omega t) sinh(sqrt(1+mu^2) omega t)/(omega sqrt(1+mu^2)).
pdyn dsolve "r'' + 2*mu*omega*r' - omega^2*r = 0" --ic "r(0)=0, r'(0)=V"
