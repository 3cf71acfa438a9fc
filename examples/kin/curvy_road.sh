#!/usr/bin/env sh
# The curvy road y = A sin(2 pi x/L) driven at constant speed V: the largest acceleration is
# A (2 pi V/L)^2 at x = L/4 (peak curvature). Keeping it below 0.2 g gives the speed limit
# V = (L/(2 pi)) sqrt(0.2 g/A).
pdyn kin --path "y = A*sin(2*pi*x/L)" --speed V --max "norm(a)" --over "x=0..L"
# With numbers (A = 2 m, L = 50 m, V = 10 m/s):
pdyn kin --path "y = A*sin(2*pi*x/L)" --speed V --set A=2,L=50,V=10 --max "norm(a)" --over "x=0..L"
