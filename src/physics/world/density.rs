//! Stage 4: SPH density and pressure (eqs 7–8), gathered per parcel.

use rayon::prelude::*;

use super::PAR_MIN;

use super::ParcelWorld;
use crate::physics::sph;

impl ParcelWorld {
    /// ρ_i = Σ_j m_j W(x_i − x_j) (self included) and p_i = K(ρ_i − ρ0_i).
    /// The rest density ρ0_i is the parcel's own isolated density m_i W(0):
    /// parcels of different masses cannot share the paper's single ρ0 = 1.28
    /// without isolated parcels feeling a pressure, so pressure here measures
    /// overlap only, is never negative (no tensile clumping) and pushes
    /// parcels apart "to prevent them getting too close" (paper §5).
    pub(super) fn sph_density(&mut self) {
        let h = self.cfg.physics.support_radius_m;
        let k = self.cfg.physics.stiffness;
        let w0 = sph::poly6(0.0, h);
        let grid = &self.grid;
        // The masses as one dense array: each neighbour costs one number
        // read, not one parcel record.
        let mut mass = std::mem::take(&mut self.scratch.mass);
        self.parcels
            .par_iter()
            .with_min_len(PAR_MIN)
            .map(|p| p.total_mass_kg())
            .collect_into_vec(&mut mass);
        // Kept for the forces; written into the parcels in the same pass.
        let mut out = std::mem::take(&mut self.scratch.density);
        out.resize(mass.len(), (0.0, 0.0));
        self.parcels
            .par_iter_mut()
            .with_min_len(PAR_MIN)
            .zip(out.par_iter_mut())
            .enumerate()
            .for_each(|(i, (p, out))| {
                let mi = mass[i];
                let mut rho = mi * w0;
                for n in grid.of(i) {
                    rho += mass[n.j] * sph::poly6(n.dist * n.dist, h);
                }
                *out = (rho, k * (rho - mi * w0));
                (p.sph_density_kg_m3, p.sph_pressure_pa) = *out;
            });
        self.scratch.density = out;
        self.scratch.mass = mass;
    }
}
