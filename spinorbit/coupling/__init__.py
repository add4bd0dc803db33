"""Couplings of the rotation core to orbit integrators (REBOUND), each behind one adapter."""
