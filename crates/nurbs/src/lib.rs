//! B-spline and NURBS curves and surfaces: evaluation, derivatives, knot operations, fitting, closest point, tessellation.
