"""Continuum–discontinuum element method for the rock: kernels and solver."""
