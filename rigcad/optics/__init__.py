"""The optical design in the meridional plane and its closed forms: paraboloid, dome (the ODE),
the 2D tracer, frames and solids for the 3D checks. No CAD kernel here: numpy and scipy only."""
