#!/usr/bin/env sh
# Circular motion at constant rate (a = -R omega^2 e_r) and in general (theta(t) a coordinate:
# a = -R theta'^2 e_r + R theta'' e_theta).
pdyn kin "[R*cos(omega*t), R*sin(omega*t), 0]"
pdyn kin --polar "r = R, theta = theta(t)"
