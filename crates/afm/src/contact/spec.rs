//! The sample file's optional `contact` and `electrostatic` objects (MODEL.md section 9,
//! docs/output-schema.md): parsed, range-checked (errors name the file, the field and the
//! allowed range) and turned into a [`TipSampleForce`].

use serde::{Deserialize, Serialize};

use super::jkr::MJ_PER_M2_IN_NN_PER_NM;
use super::{
    CapillaryContact, ContactLaw, DmtContact, DoubleLayer, FilmContact, FilmCorrection, HertzShape,
    HertzTip, HydrationForce, JkrContact, KelvinVoigtContact, StandardLinearSolid, TipSampleForce,
};
use crate::error::AfmError;
use crate::validation::{check, invalid, Interval};

fn clip_by_default() -> bool {
    true
}

/// Water's surface tension at 20 C, mN/m (Israelachvili 2011, table 17.1).
fn water_surface_tension() -> f64 {
    72.8
}

/// Room temperature, K.
fn room_temperature() -> f64 {
    293.15
}

/// Water's molar volume, m^3/mol.
fn water_molar_volume() -> f64 {
    18.0e-6
}

/// The tip's shape for the Hertz law.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TipShapeSpec {
    /// A sphere of the cantilever's tip radius (the default).
    #[default]
    Sphere,
    /// A cone with `cone_half_angle_deg`.
    Cone,
    /// A flat punch with `punch_radius_nm`.
    FlatPunch,
}

/// The film's bottom-effect correction ([`FilmCorrection`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FilmCorrectionSpec {
    /// Garcia & Garcia 2018 (the default).
    #[default]
    #[serde(rename = "garcia-2018")]
    Garcia2018,
    /// Dimitriadis et al. 2002, bonded film.
    #[serde(rename = "dimitriadis-2002-bonded")]
    Dimitriadis2002Bonded,
    /// Dimitriadis et al. 2002, non-bonded film.
    #[serde(rename = "dimitriadis-2002-non-bonded")]
    Dimitriadis2002NonBonded,
}

/// The `contact` object of a sample file; absent means `{"law": "hertz"}` with a sphere.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "law", rename_all = "kebab-case", deny_unknown_fields)]
pub enum ContactSpec {
    /// Hertz on a half-space; `tip_shape` `sphere` (default, the cantilever's tip radius),
    /// `cone` (needs `cone_half_angle_deg`, range [1, 89] deg) or `flat-punch` (needs
    /// `punch_radius_nm`, range (0, 1e4] nm).
    Hertz {
        /// The tip's shape.
        #[serde(default)]
        tip_shape: TipShapeSpec,
        /// The cone's half-angle, degrees.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        cone_half_angle_deg: Option<f64>,
        /// The punch's radius, nm.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        punch_radius_nm: Option<f64>,
    },
    /// DMT: Hamaker constant `H` in J, range [0, 1e-18]; intermolecular distance `a0` in nm,
    /// range [0.05, 2].
    Dmt {
        /// `H`, J.
        hamaker_constant_j: f64,
        /// `a0`, nm.
        intermolecular_distance_nm: f64,
    },
    /// Kelvin-Voigt: sample viscosity `eta` in Pa s, range [0, 1e6]; `clip` (default true).
    KelvinVoigt {
        /// `eta`, Pa s.
        viscosity_pa_s: f64,
        /// Whether the force is clipped at zero.
        #[serde(default = "clip_by_default")]
        clip: bool,
    },
    /// A film on a rigid substrate: thickness in nm, range (0, 1e5]; the correction.
    Film {
        /// `h`, nm.
        thickness_nm: f64,
        /// The bottom-effect correction.
        #[serde(default)]
        correction: FilmCorrectionSpec,
    },
    /// A standard linear solid (MODEL.md section 9): instantaneous modulus `E_0` and relaxed
    /// modulus `E_inf` in GPa, range [1e-7, 1e4] with `E_inf <= E_0`; relaxation time `tau` in
    /// us, range [1e-3, 1e6]. They replace the sample's `youngs_modulus_gpa` in the contact.
    StandardLinearSolid {
        /// `E_0`, GPa.
        instant_modulus_gpa: f64,
        /// `E_inf`, GPa.
        relaxed_modulus_gpa: f64,
        /// `tau`, us.
        relaxation_time_us: f64,
    },
    /// JKR adhesion of the cantilever's spherical tip: work of adhesion `W` in mJ/m^2, range
    /// [0, 1000]; `W = 0` is the Hertz sphere exactly (the law built is Hertz's).
    Jkr {
        /// `W`, mJ/m^2.
        work_of_adhesion_mj_per_m2: f64,
    },
    /// Hertz sphere plus a capillary meniscus in air: relative humidity `RH` in [0.01, 0.99];
    /// surface tension in mN/m, range (0, 500] (default water's 72.8); contact angle in deg,
    /// range [0, 89] (default 0); temperature in K, range [250, 400] (default 293.15); the
    /// liquid's molar volume in m^3/mol, range (0, 1e-3] (default water's 18.0e-6).
    Capillary {
        /// `RH`, 0 to 1.
        relative_humidity: f64,
        /// `gamma`, mN/m.
        #[serde(default = "water_surface_tension")]
        surface_tension_mn_per_m: f64,
        /// `theta`, deg.
        #[serde(default)]
        contact_angle_deg: f64,
        /// `T`, K.
        #[serde(default = "room_temperature")]
        temperature_k: f64,
        /// `V_m`, m^3/mol.
        #[serde(default = "water_molar_volume")]
        molar_volume_m3_per_mol: f64,
    },
}

/// The `hydration` object of a sample file: the solvation force of ordered water layers added
/// to the contact law (MODEL.md section 9, [`HydrationForce`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HydrationSpec {
    /// The pressure amplitude `P_0` between flat surfaces at contact, MPa; range [-1e4, 1e4]
    /// (positive: repulsive at contact).
    pub pressure_mpa: f64,
    /// The layer spacing `sigma` (about a water molecule's diameter, 0.25-0.3 nm), nm; range
    /// [0.05, 5].
    pub layer_spacing_nm: f64,
    /// The decay length `lambda`, nm; range [0.05, 10].
    pub decay_length_nm: f64,
}

impl HydrationSpec {
    /// Check every parameter's range; errors name `file` and `hydration.<field>`.
    pub fn validate(&self, file: &str) -> Result<(), AfmError> {
        check(
            file,
            "hydration.pressure_mpa",
            self.pressure_mpa,
            Interval::closed(-1e4, 1e4, "MPa"),
        )?;
        check(
            file,
            "hydration.layer_spacing_nm",
            self.layer_spacing_nm,
            Interval::closed(0.05, 5.0, "nm"),
        )?;
        check(
            file,
            "hydration.decay_length_nm",
            self.decay_length_nm,
            Interval::closed(0.05, 10.0, "nm"),
        )
    }

    /// The hydration force on a tip of radius `R` (nm).
    pub fn force(&self, tip_radius_nm: f64) -> HydrationForce {
        HydrationForce::new(
            tip_radius_nm,
            self.pressure_mpa,
            self.layer_spacing_nm,
            self.decay_length_nm,
        )
    }
}

/// The `electrostatic` object of a sample file: a double layer added to the contact law.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ElectrostaticSpec {
    /// The Debye length `lambda_D`, nm; range (0, 1000].
    pub debye_length_nm: f64,
    /// The tip's surface charge `sigma_t`, C/m^2; range [-1, 1].
    pub tip_charge_c_per_m2: f64,
    /// The sample's surface charge `sigma_s`, C/m^2; range [-1, 1].
    pub sample_charge_c_per_m2: f64,
    /// The medium's relative permittivity `eps_r`; range [1, 200].
    pub relative_permittivity: f64,
}

impl ContactSpec {
    /// Check every parameter's range; errors name `file` and the field (`contact.<field>`).
    pub fn validate(&self, file: &str) -> Result<(), AfmError> {
        match self {
            Self::Hertz {
                tip_shape,
                cone_half_angle_deg,
                punch_radius_nm,
            } => check_tip_shape(file, *tip_shape, *cone_half_angle_deg, *punch_radius_nm),
            Self::Dmt {
                hamaker_constant_j,
                intermolecular_distance_nm,
            } => {
                check(
                    file,
                    "contact.hamaker_constant_j",
                    *hamaker_constant_j,
                    Interval::closed(0.0, 1e-18, "J"),
                )?;
                check(
                    file,
                    "contact.intermolecular_distance_nm",
                    *intermolecular_distance_nm,
                    Interval::closed(0.05, 2.0, "nm"),
                )
            }
            Self::KelvinVoigt { viscosity_pa_s, .. } => check(
                file,
                "contact.viscosity_pa_s",
                *viscosity_pa_s,
                Interval::closed(0.0, 1e6, "Pa s"),
            ),
            Self::Film { thickness_nm, .. } => check(
                file,
                "contact.thickness_nm",
                *thickness_nm,
                Interval::positive(1e5, "nm"),
            ),
            Self::StandardLinearSolid {
                instant_modulus_gpa,
                relaxed_modulus_gpa,
                relaxation_time_us,
            } => {
                check(
                    file,
                    "contact.instant_modulus_gpa",
                    *instant_modulus_gpa,
                    Interval::closed(1e-7, 1e4, "GPa"),
                )?;
                check(
                    file,
                    "contact.relaxed_modulus_gpa",
                    *relaxed_modulus_gpa,
                    Interval::closed(1e-7, *instant_modulus_gpa, "GPa"),
                )?;
                check(
                    file,
                    "contact.relaxation_time_us",
                    *relaxation_time_us,
                    Interval::closed(1e-3, 1e6, "us"),
                )
            }
            Self::Jkr {
                work_of_adhesion_mj_per_m2,
            } => check(
                file,
                "contact.work_of_adhesion_mj_per_m2",
                *work_of_adhesion_mj_per_m2,
                Interval::closed(0.0, 1000.0, "mJ/m^2"),
            ),
            Self::Capillary {
                relative_humidity,
                surface_tension_mn_per_m,
                contact_angle_deg,
                temperature_k,
                molar_volume_m3_per_mol,
            } => {
                check(
                    file,
                    "contact.relative_humidity",
                    *relative_humidity,
                    Interval::closed(0.01, 0.99, ""),
                )?;
                check(
                    file,
                    "contact.surface_tension_mn_per_m",
                    *surface_tension_mn_per_m,
                    Interval::positive(500.0, "mN/m"),
                )?;
                check(
                    file,
                    "contact.contact_angle_deg",
                    *contact_angle_deg,
                    Interval::closed(0.0, 89.0, "deg"),
                )?;
                check(
                    file,
                    "contact.temperature_k",
                    *temperature_k,
                    Interval::closed(250.0, 400.0, "K"),
                )?;
                check(
                    file,
                    "contact.molar_volume_m3_per_mol",
                    *molar_volume_m3_per_mol,
                    Interval::positive(1e-3, "m^3/mol"),
                )
            }
        }
    }

    /// The sample moduli a law uses in place of the sample's `youngs_modulus_gpa`: a standard
    /// linear solid's `(E_0, E_inf)`, GPa; `None` for every other law.
    pub fn sample_moduli_gpa(&self) -> Option<(f64, f64)> {
        match *self {
            Self::StandardLinearSolid {
                instant_modulus_gpa,
                relaxed_modulus_gpa,
                ..
            } => Some((instant_modulus_gpa, relaxed_modulus_gpa)),
            _ => None,
        }
    }

    /// The law for reduced modulus `E*` (GPa), tip radius `R` (nm) and sample Poisson ratio
    /// `nu_s` (for `eta* = eta / (1 - nu_s^2)`). Call after [`ContactSpec::validate`]. A
    /// standard linear solid takes `E*` as its instantaneous reduced modulus and scales its
    /// relaxed one by `E_inf/E_0` (exact for a rigid tip); the tapping model replaces both by
    /// the reduced moduli of `E_0` and `E_inf` with the tip's.
    pub fn law(&self, effective_modulus_gpa: f64, tip_radius_nm: f64, poisson: f64) -> ContactLaw {
        let e = effective_modulus_gpa;
        match *self {
            Self::StandardLinearSolid {
                instant_modulus_gpa,
                relaxed_modulus_gpa,
                relaxation_time_us,
            } => ContactLaw::StandardLinearSolid(StandardLinearSolid {
                instant_modulus_gpa: e,
                relaxed_modulus_gpa: e * relaxed_modulus_gpa / instant_modulus_gpa,
                relaxation_time_us,
                tip_radius_nm,
            }),
            Self::Hertz {
                tip_shape,
                cone_half_angle_deg,
                punch_radius_nm,
            } => {
                let tip = match tip_shape {
                    TipShapeSpec::Sphere => HertzTip::Sphere {
                        radius_nm: tip_radius_nm,
                    },
                    TipShapeSpec::Cone => HertzTip::Cone {
                        half_angle_deg: cone_half_angle_deg.unwrap_or(f64::NAN),
                    },
                    TipShapeSpec::FlatPunch => HertzTip::FlatPunch {
                        radius_nm: punch_radius_nm.unwrap_or(f64::NAN),
                    },
                };
                ContactLaw::Hertz(HertzShape {
                    effective_modulus_gpa: e,
                    tip,
                })
            }
            Self::Dmt {
                hamaker_constant_j,
                intermolecular_distance_nm,
            } => ContactLaw::Dmt(DmtContact {
                effective_modulus_gpa: e,
                tip_radius_nm,
                hamaker_constant_j,
                intermolecular_distance_nm,
            }),
            Self::KelvinVoigt {
                viscosity_pa_s,
                clip,
            } => ContactLaw::KelvinVoigt(KelvinVoigtContact {
                effective_modulus_gpa: e,
                tip_radius_nm,
                effective_viscosity_pa_s: viscosity_pa_s / (1.0 - poisson * poisson),
                clip,
            }),
            Self::Film {
                thickness_nm,
                correction,
            } => ContactLaw::Film(FilmContact {
                effective_modulus_gpa: e,
                tip_radius_nm,
                thickness_nm,
                correction: match correction {
                    FilmCorrectionSpec::Garcia2018 => FilmCorrection::Garcia2018,
                    FilmCorrectionSpec::Dimitriadis2002Bonded => {
                        FilmCorrection::Dimitriadis2002Bonded
                    }
                    FilmCorrectionSpec::Dimitriadis2002NonBonded => {
                        FilmCorrection::Dimitriadis2002NonBonded
                    }
                },
            }),
            // W = 0: JKR's relations are Hertz's, and the law is Hertz's (its fast paths).
            Self::Jkr {
                work_of_adhesion_mj_per_m2: 0.0,
            } => ContactLaw::Hertz(sphere(e, tip_radius_nm)),
            Self::Jkr {
                work_of_adhesion_mj_per_m2,
            } => ContactLaw::Jkr(JkrContact::new(
                e,
                tip_radius_nm,
                work_of_adhesion_mj_per_m2 * MJ_PER_M2_IN_NN_PER_NM,
            )),
            Self::Capillary {
                relative_humidity,
                surface_tension_mn_per_m,
                contact_angle_deg,
                temperature_k,
                molar_volume_m3_per_mol,
            } => ContactLaw::Capillary(CapillaryContact::new(
                sphere(e, tip_radius_nm),
                tip_radius_nm,
                relative_humidity,
                surface_tension_mn_per_m,
                contact_angle_deg,
                temperature_k,
                molar_volume_m3_per_mol,
            )),
        }
    }
}

/// The Hertz sphere of reduced modulus `E*` (GPa) and radius `R` (nm).
fn sphere(effective_modulus_gpa: f64, tip_radius_nm: f64) -> HertzShape {
    HertzShape {
        effective_modulus_gpa,
        tip: HertzTip::Sphere {
            radius_nm: tip_radius_nm,
        },
    }
}

fn check_tip_shape(
    file: &str,
    shape: TipShapeSpec,
    half_angle: Option<f64>,
    punch_radius: Option<f64>,
) -> Result<(), AfmError> {
    let (needed, given, unused, interval) = match shape {
        TipShapeSpec::Sphere => {
            for (field, value) in [
                ("contact.cone_half_angle_deg", half_angle),
                ("contact.punch_radius_nm", punch_radius),
            ] {
                if let Some(value) = value {
                    return Err(invalid(
                        file,
                        field,
                        value,
                        "absent for tip_shape `sphere` (the cantilever's tip radius is used)"
                            .to_string(),
                    ));
                }
            }
            return Ok(());
        }
        TipShapeSpec::Cone => (
            "contact.cone_half_angle_deg",
            half_angle,
            ("contact.punch_radius_nm", punch_radius),
            Interval::closed(1.0, 89.0, "deg"),
        ),
        TipShapeSpec::FlatPunch => (
            "contact.punch_radius_nm",
            punch_radius,
            ("contact.cone_half_angle_deg", half_angle),
            Interval::positive(1e4, "nm"),
        ),
    };
    if let (field, Some(value)) = unused {
        return Err(invalid(
            file,
            field,
            value,
            "absent for this tip_shape".to_string(),
        ));
    }
    match given {
        Some(value) => check(file, needed, value, interval),
        None => Err(invalid(
            file,
            needed,
            f64::NAN,
            "a number, required for this tip_shape".to_string(),
        )),
    }
}

impl ElectrostaticSpec {
    /// Check every parameter's range; errors name `file` and `electrostatic.<field>`.
    pub fn validate(&self, file: &str) -> Result<(), AfmError> {
        check(
            file,
            "electrostatic.debye_length_nm",
            self.debye_length_nm,
            Interval::positive(1000.0, "nm"),
        )?;
        check(
            file,
            "electrostatic.tip_charge_c_per_m2",
            self.tip_charge_c_per_m2,
            Interval::closed(-1.0, 1.0, "C/m^2"),
        )?;
        check(
            file,
            "electrostatic.sample_charge_c_per_m2",
            self.sample_charge_c_per_m2,
            Interval::closed(-1.0, 1.0, "C/m^2"),
        )?;
        check(
            file,
            "electrostatic.relative_permittivity",
            self.relative_permittivity,
            Interval::closed(1.0, 200.0, ""),
        )
    }

    /// The double layer for a tip of radius `R` (nm).
    pub fn double_layer(&self, tip_radius_nm: f64) -> DoubleLayer {
        DoubleLayer::new(
            tip_radius_nm,
            self.tip_charge_c_per_m2,
            self.sample_charge_c_per_m2,
            self.relative_permittivity,
            self.debye_length_nm,
        )
    }
}

/// The tip-sample force of a sample's `contact` (`None`: Hertz with a sphere) and
/// `electrostatic` objects, for reduced modulus `E*` (GPa), tip radius `R` (nm) and sample
/// Poisson ratio `nu_s`.
pub fn tip_sample_force(
    contact: Option<&ContactSpec>,
    electrostatic: Option<&ElectrostaticSpec>,
    effective_modulus_gpa: f64,
    tip_radius_nm: f64,
    poisson: f64,
) -> TipSampleForce {
    let law = match contact {
        Some(spec) => spec.law(effective_modulus_gpa, tip_radius_nm, poisson),
        None => ContactLaw::Hertz(HertzShape {
            effective_modulus_gpa,
            tip: HertzTip::Sphere {
                radius_nm: tip_radius_nm,
            },
        }),
    };
    TipSampleForce {
        law,
        double_layer: electrostatic.map(|spec| spec.double_layer(tip_radius_nm)),
        hydration: None,
    }
}
