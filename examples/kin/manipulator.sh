#!/usr/bin/env sh
# A manipulator arm turning at constant rate omega extends at constant rate c from r = 0 to R:
# a = -c t omega^2 e_r + 2 c omega e_theta (note the factor 2 on the Coriolis term).
# |a| grows with r, so |a| <= a_max binds at full extension (t = R/c):
# c_max = sqrt(a_max^2 - R^2 omega^4)/(2 omega).
pdyn kin --polar "r = c*t, theta = omega*t" --at t=R/c
# Numbers (omega = 2 rad/s, R = 0.5 m, c = c_max for a_max = 3 m/s^2): the maximum is a_max, at the end.
pdyn kin --polar "r = c*t, theta = omega*t" --set "omega=2,R=0.5,c=sqrt(9 - 4)/4" --max "norm(a)" --over "t=0..R/c"
