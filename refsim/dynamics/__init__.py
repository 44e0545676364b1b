"""Rigid-body dynamics (seed S5, S7, S8, S9) and the simulation loop."""
