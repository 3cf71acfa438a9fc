#!/usr/bin/env sh
# Vehicle suspension released from length L: x(t) = (L - L0 + mg/k) cos(sqrt(k/m) t) + L0 - mg/k.
pdyn dsolve "m*x'' = -k*(x - L0) - m*g" --ic "x(0)=L, x'(0)=0"
