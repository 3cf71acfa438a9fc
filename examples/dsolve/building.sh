#!/usr/bin/env sh
# Two-storey building shaken at its base, u = 0.01 sin(5t) (SI units): exact solution by numeric
# eigen-decomposition (the tests compare it with RK4 to 1e-6).
pdyn dsolve "2000*x1'' = -4e5*(x1 - 0.01*sin(5*t)) - 3e5*(x1 - x2) - 800*x1'" \
            "1500*x2'' = -3e5*(x2 - x1)" \
            --ic "x1(0)=0.02, x1'(0)=0, x2(0)=0, x2'(0)=0.1" --at 0.5,1,2
# Symbolic masses and stiffnesses: normal modes exactly (symmetric chain: sqrt(k/m), sqrt(3k/m)).
pdyn dsolve "m*x1'' = -2*k*x1 + k*x2" "m*x2'' = k*x1 - 2*k*x2" --ic "x1(0)=a, x1'(0)=0, x2(0)=0, x2'(0)=0"
