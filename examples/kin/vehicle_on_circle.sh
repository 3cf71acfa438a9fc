#!/usr/bin/env sh
# A vehicle starts from rest and speeds up uniformly around half a circle of radius R in time T:
# theta = pi t^2/T^2. Its acceleration is largest at the end, |a(T)| = 2 pi R sqrt(1+4 pi^2)/T^2;
# no skidding (|a| <= mu g) needs T >= sqrt(2 pi R/(mu g)) (1 + 4 pi^2)^(1/4).
pdyn kin --polar "r = R, theta = pi*t^2/T^2" --at t=T --max "norm(a)" --over "t=0..T"
