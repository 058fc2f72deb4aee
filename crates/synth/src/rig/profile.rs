//! The rig twin's Monte Carlo profiles: what to simulate per channel (`ProfileSpec`), the
//! simulated profile with its standard errors (`McProfile`, cached on disk), and its smoothing
//! (`SmoothProfile`, local quadratic fits in the profile's noise).

use super::*;

/// What an MC profile is made of; two equal specs give the same profile bit for bit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ProfileSpec {
    /// σ′s [mm⁻¹].
    pub sigma_s_prime: f64,
    /// σa [mm⁻¹].
    pub sigma_a: f64,
    /// η.
    pub eta: f64,
    /// Henyey–Greenstein g.
    pub g: f64,
    /// Uniform disk beam radius \[mm\] (the 1/e² radius of a Gaussian beam when `gaussian`).
    pub spot_radius_mm: f64,
    /// A Gaussian beam instead of a uniform disk (absent from the JSON when false, so the cache
    /// names of disk profiles are those made before the field existed).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub gaussian: bool,
    /// Radial bin edges \[mm\].
    pub edges: Vec<f64>,
    /// Photons.
    pub photons: u64,
    /// Seed.
    pub seed: u64,
}

impl ProfileSpec {
    /// The spec for one channel of a rig: bins of 0.025 mm out to two spot diameters, then 140
    /// logarithmic bins to the image corner.
    ///
    /// # Errors
    /// [`SynthError::Mc`] when the grid cannot be built.
    pub fn for_channel(
        sigma_s_prime: f64,
        sigma_a: f64,
        eta: f64,
        rig: &RigSpec,
        seed: u64,
    ) -> Result<Self, SynthError> {
        let inner = 4.0 * rig.spot_radius_mm;
        let n_inner = (inner / 0.025).round().max(8.0) as usize;
        let mut edges: Vec<f64> = (0..=n_inner)
            .map(|i| inner * i as f64 / n_inner as f64)
            .collect();
        let outer = rig.corner_mm().max(inner * 2.0);
        let n_log = 140;
        let q = (outer / inner).ln() / n_log as f64;
        edges.extend((1..=n_log).map(|i| inner * (q * i as f64).exp()));
        RadialGrid::from_edges(edges.clone())?;
        Ok(Self {
            sigma_s_prime,
            sigma_a,
            eta,
            g: rig.g,
            spot_radius_mm: rig.spot_radius_mm,
            gaussian: rig.effects.gaussian_spot,
            edges,
            photons: photons_for(sigma_s_prime, sigma_a, rig),
            seed,
        })
    }

    /// A short stable hash of the spec (FNV-1a 64 of its JSON) for the cache file name.
    pub fn fingerprint(&self) -> String {
        let json = serde_json::to_string(self).unwrap_or_default();
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for b in json.bytes() {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
        format!("{h:016x}")
    }
}

/// A Monte Carlo radial profile of one channel under the rig's disk beam.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct McProfile {
    pub(super) format: String,
    /// The spec that made it.
    pub spec: ProfileSpec,
    /// Area-weighted bin centres \[mm\].
    pub centers: Vec<f64>,
    /// Rd per bin [mm⁻²].
    pub value: Vec<f64>,
    /// Standard error per bin [mm⁻²].
    pub stderr: Vec<f64>,
    /// Total diffuse reflectance (excludes the specular reflection).
    pub rd_total: McMean,
}

pub(super) const PROFILE_FORMAT: &str = "scatterfit-synth-mc-profile-v1";

impl McProfile {
    /// Runs the simulation on the current rayon pool; `progress(done, total)` counts photons.
    ///
    /// # Errors
    /// [`SynthError::Mc`] for coefficients the engine refuses.
    pub fn simulate(
        spec: &ProfileSpec,
        progress: &(dyn Fn(u64, u64) + Sync),
    ) -> Result<Self, SynthError> {
        let layer = Layer::from_reduced(
            spec.sigma_s_prime,
            spec.sigma_a,
            spec.g,
            spec.eta,
            f64::INFINITY,
        )?;
        let grid = RadialGrid::from_edges(spec.edges.clone())?;
        let beam = Beam::new(if spec.gaussian {
            BeamProfile::Gaussian {
                radius: spec.spot_radius_mm,
            }
        } else {
            BeamProfile::Disk {
                radius: spec.spot_radius_mm,
            }
        })?;
        let sim = Simulation::new(
            Sample::slab(layer, 1.0)?,
            beam,
            grid.clone(),
            spec.photons,
            spec.seed,
        )?;
        let total = spec.photons;
        let r = sim.run_with_progress(&|n| progress(n, total));
        Ok(Self {
            format: PROFILE_FORMAT.into(),
            spec: spec.clone(),
            centers: (0..grid.bins()).map(|i| grid.center(i)).collect(),
            value: r.rd_profile.iter().map(|e| e.value).collect(),
            stderr: r.rd_profile.iter().map(|e| e.stderr).collect(),
            rd_total: r.rd_total,
        })
    }

    /// The profile for `spec` from the cache folder when a file made with the same spec is there,
    /// else simulated and saved there (atomically). Returns whether it was loaded.
    ///
    /// # Errors
    /// As [`McProfile::simulate`], or [`SynthError::Io`] when the cache cannot be written.
    pub fn load_or_simulate(
        spec: &ProfileSpec,
        cache_dir: Option<&Path>,
        progress: &(dyn Fn(u64, u64) + Sync),
    ) -> Result<(Self, bool), SynthError> {
        let Some(dir) = cache_dir else {
            return Ok((Self::simulate(spec, progress)?, false));
        };
        let path = dir.join(format!("synth-profile-{}.json", spec.fingerprint()));
        if let Ok(text) = scatterfit_safefs::read::read_to_string_limited(
            &path,
            scatterfit_safefs::MAX_TEXT_BYTES,
        ) && let Ok(p) = serde_json::from_str::<Self>(&text)
            && p.format == PROFILE_FORMAT
            && p.spec == *spec
            && p.value.len() + 1 == spec.edges.len()
            && p.is_usable()
        {
            return Ok((p, true));
        }
        // A corrupt file (unreadable, or numbers no simulation gives) is simulated again and
        // replaced; a cache that cannot take the file fails now, before the Monte Carlo work, and
        // is blamed by name.
        scatterfit_mc::cache::prepare_write(&path)?;
        let p = Self::simulate(spec, progress)?;
        scatterfit_mc::cache::write_atomic(&path, &serde_json::to_vec(&p).unwrap_or_default())?;
        Ok((p, false))
    }

    /// True when the numbers are ones a simulation gives: finite, non-negative, increasing bin
    /// centres, Rd within [0, 1], and smooth enough to render ([`SmoothProfile::new`]). What a
    /// cached profile must be to be reused.
    fn is_usable(&self) -> bool {
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite() && *x >= 0.0);
        self.value.len() == self.stderr.len()
            && self.value.len() == self.centers.len()
            && finite(&self.value)
            && finite(&self.stderr)
            && finite(&self.centers)
            && self.centers.windows(2).all(|w| w[0] < w[1])
            && (0.0..=1.0).contains(&self.rd_total.value)
            && self.rd_total.stderr.is_finite()
            && SmoothProfile::new(self).is_ok()
    }
}

/// A Monte Carlo profile made smooth enough to render: ln Rd interpolated linearly between bin
/// centres; beyond twice the spot radius, bins noisier than 0.5 % are replaced by a weighted local
/// quadratic fit of ln Rd over ±4 bins (a LOESS-style smoother: the noise of one bin would
/// otherwise show as a ring in the images, correlated over its pixels); past the last bin with a
/// usable estimate, ln(r² Rd) continues linearly (the far field e^{−σtr r}/r²).
#[derive(Debug, Clone, PartialEq)]
pub struct SmoothProfile {
    r: Vec<f64>,
    ln_rd: Vec<f64>,
    tail_slope: f64,
}

impl SmoothProfile {
    /// Smooths `p`.
    ///
    /// # Errors
    /// [`SynthError::InvalidParameter`] when fewer than four bins hold usable estimates.
    pub fn new(p: &McProfile) -> Result<Self, SynthError> {
        let good: Vec<usize> = (0..p.value.len())
            .filter(|&i| p.value[i] > 0.0 && p.stderr[i] < 0.5 * p.value[i])
            .collect();
        if good.len() < 4 {
            return Err(SynthError::InvalidParameter {
                name: "profile bins",
                value: good.len() as f64,
                reason: "fewer than 4 bins with a usable Monte Carlo estimate: raise the photon count",
            });
        }
        let r: Vec<f64> = good.iter().map(|&i| p.centers[i]).collect();
        let raw: Vec<f64> = good.iter().map(|&i| p.value[i].ln()).collect();
        let sig: Vec<f64> = good
            .iter()
            .map(|&i| (p.stderr[i] / p.value[i]).max(1e-4))
            .collect();
        let smooth_from = 2.0 * p.spec.spot_radius_mm;
        let ln_rd: Vec<f64> = (0..r.len())
            .map(|k| {
                if r[k] < smooth_from || sig[k] < 5e-3 {
                    return raw[k];
                }
                local_quadratic(&r, &raw, &sig, k, 4)
            })
            .collect();
        // Tail: slope of ln(r²Rd) over the last (up to) eight usable bins.
        let n = r.len();
        let from = n.saturating_sub(8);
        let xs: Vec<f64> = r[from..].to_vec();
        let ys: Vec<f64> = (from..n).map(|k| ln_rd[k] + 2.0 * r[k].ln()).collect();
        let mx = xs.iter().sum::<f64>() / xs.len() as f64;
        let my = ys.iter().sum::<f64>() / ys.len() as f64;
        let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
        let sxx: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
        let tail_slope = if sxx > 0.0 { (sxy / sxx).min(0.0) } else { 0.0 };
        Ok(Self {
            r,
            ln_rd,
            tail_slope,
        })
    }

    /// Rd at radius `r_mm` [mm⁻²].
    pub fn at(&self, r_mm: f64) -> f64 {
        let (r, y) = (&self.r, &self.ln_rd);
        let n = r.len();
        if r_mm <= r[0] {
            return y[0].exp();
        }
        if r_mm >= r[n - 1] {
            let last = r[n - 1];
            return (y[n - 1] + 2.0 * (last / r_mm).ln() + self.tail_slope * (r_mm - last)).exp();
        }
        let j = r.partition_point(|&x| x <= r_mm) - 1;
        let t = (r_mm - r[j]) / (r[j + 1] - r[j]);
        (y[j] * (1.0 - t) + y[j + 1] * t).exp()
    }
}

/// Weighted least-squares quadratic through (r, y) over indices k − h … k + h, evaluated at r[k].
pub(super) fn local_quadratic(r: &[f64], y: &[f64], sig: &[f64], k: usize, h: usize) -> f64 {
    let (lo, hi) = (k.saturating_sub(h), (k + h + 1).min(r.len()));
    if hi - lo < 4 {
        return y[k];
    }
    // Normal equations for a + b u + c u², u = r − r[k].
    let mut m = [[0.0f64; 3]; 3];
    let mut v = [0.0f64; 3];
    for i in lo..hi {
        let u = r[i] - r[k];
        let w = 1.0 / (sig[i] * sig[i]);
        let b = [1.0, u, u * u];
        for a in 0..3 {
            v[a] += w * b[a] * y[i];
            for c in 0..3 {
                m[a][c] += w * b[a] * b[c];
            }
        }
    }
    let det = |m: &[[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(&m);
    if !(d.is_finite() && d.abs() > 0.0) {
        return y[k];
    }
    // Cramer's rule for the constant term a.
    let mut ma = m;
    for (row, &val) in ma.iter_mut().zip(&v) {
        row[0] = val;
    }
    let a = det(&ma) / d;
    if a.is_finite() { a } else { y[k] }
}
