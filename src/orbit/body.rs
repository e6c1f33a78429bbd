//! The central body: gravitational parameter, size, oblateness and rotation.

/// Physical constants of the body the spacecraft orbits (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CentralBody {
    /// Name, lower case (`"earth"`).
    pub name: &'static str,
    /// Gravitational parameter μ = GM (m³/s²).
    pub mu: f64,
    /// Equatorial radius R (m); altitudes are measured above a sphere of this radius.
    pub radius: f64,
    /// Unnormalised second zonal harmonic J2 (dimensionless).
    pub j2: f64,
    /// Rotation rate ω_E about the body's z axis (rad/s).
    pub rotation_rate: f64,
}

impl CentralBody {
    /// The Earth.
    ///
    /// - μ = 3.986004418e14 m³/s²: WGS-84 (NIMA TR8350.2, 3rd ed., Table 3.1, GM including
    ///   the atmosphere), the value of EGM96.
    /// - R = 6378.137 km: WGS-84 semi-major axis (NIMA TR8350.2, Table 3.1).
    /// - J2 = 1.08262668e-3: EGM96 unnormalised, J2 = −√5 C̄₂₀ with
    ///   C̄₂₀ = −0.484165371736e-3 (Lemoine et al., NASA/TP-1998-206861).
    /// - ω_E = 7.292115e-5 rad/s: WGS-84 (NIMA TR8350.2, Table 3.1).
    pub const EARTH: CentralBody = CentralBody {
        name: "earth",
        mu: 3.986_004_418e14,
        radius: 6_378_137.0,
        j2: 1.082_626_68e-3,
        rotation_rate: 7.292_115e-5,
    };

    /// Names accepted by [`CentralBody::by_name`].
    pub const KNOWN: &'static [&'static str] = &["earth"];

    /// The body of that name (case-insensitive, surrounding blanks ignored).
    pub fn by_name(name: &str) -> Result<CentralBody, String> {
        match name.trim().to_ascii_lowercase().as_str() {
            "earth" => Ok(Self::EARTH),
            _ => Err(format!(
                "unknown central body `{}`: known bodies are {}",
                name.trim(),
                Self::KNOWN
                    .iter()
                    .map(|k| format!("`{k}`"))
                    .collect::<Vec<_>>()
                    .join(", ")
            )),
        }
    }
}
