#!/usr/bin/env sh
# Projectile without drag; the Kremlin stone: 25 mph at 45 degrees from 71 m lands after about
# 4.694 s, 37.1 m away (g = 9.81).
pdyn dsolve "x'' = 0" "y'' = -g" --ic "x(0)=0, x'(0)=V*cos(alpha), y(0)=h, y'(0)=V*sin(alpha)"
pdyn dsolve "x'' = 0" "y'' = -g" --ic "x(0)=0, x'(0)=V*cos(alpha), y(0)=h, y'(0)=V*sin(alpha)" \
  --set "g=9.81,V=25*0.44704,alpha=pi/4,h=71" --when "y = 0"
# Nanoparticle launched upward with kinetic energy kT: highest point kT/(m g) where y' = 0.
pdyn dsolve "y'' = -g" --ic "y(0)=0, y'(0)=sqrt(2*k*T/m)" --when "y' = 0"
