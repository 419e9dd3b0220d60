//! Independent verification: tri-dexel stock simulation, overcut/residual maps, holder and shank collisions.
