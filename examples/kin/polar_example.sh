#!/usr/bin/env sh
# Chapter 3.1, polar example: theta = t^2, r = t/sqrt(pi), evaluated where theta = pi.
# Expect r = -i, v = -(1/sqrt(pi)) i - 2 sqrt(pi) j, a = -4 pi e_r + 6 e_theta,
# a_t = 8 pi/sqrt(1+4 pi^2), a_n = (8 pi^2 + 6)/sqrt(1+4 pi^2), n = (-2 pi e_r + e_theta)/sqrt(1+4 pi^2).
pdyn kin --polar "r = t/sqrt(pi), theta = t^2" --at theta=pi
