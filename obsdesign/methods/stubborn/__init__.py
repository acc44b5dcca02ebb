"""The ``stubborn`` method: stubborn observers with an adaptive saturation level (paper 002:
Astolfi, Alessandri, Zaccarian, "Stubborn observers for linear and nonlinear systems", WUDS
2017)."""

from obsdesign.methods.stubborn.method import METHOD

__all__ = ["METHOD"]
