//! Rayleigh-Ritz stiffness indicator of tapered (conical) cutters and its gradient.
