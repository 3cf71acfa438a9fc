#!/usr/bin/env sh
# A manipulator arm turning at constant rate omega extends at constant rate c from r = 0:
# a = -c t omega^2 e_r + 2 c omega e_theta. At the start only the Coriolis term acts, so
# |a| <= a_max allows c <= a_max/(2 omega) (note the factor 2).
pdyn kin --polar "r = c*t, theta = omega*t" --at t=0
