//! Quantities a case can measure, parsed from the case's `quantity` string.

use data::{ModalResult, RunResult, Scene, StaticResult, channel};

/// What to extract from a backend's answer.
#[derive(Debug, Clone, PartialEq)]
pub enum Quantity {
    /// N-th natural frequency (1-based), optionally only among modes of a kind.
    Frequency { n: usize, kind: Option<String> },
    /// Static tip deflection of the last link.
    StaticTip,
    /// A channel's (or an energy-ledger term's, `energy.NAME`) value at time t.
    At { channel: String, t: f64 },
    /// max |channel| (or |ledger term|) over the run.
    Peak { channel: String },
    /// The whole time history of a channel (or of an energy-ledger term, `energy.NAME`);
    /// compared with another backend's history as max_t |a(t) − b(t)| / max_t |b(t)|, after a
    /// zero-phase low-pass with cut-off `lowpass_hz` when given (see [`super::filter`]).
    History {
        channel: String,
        lowpass_hz: Option<f64>,
    },
    /// Relative energy-ledger closure.
    LedgerClosure,
    /// Largest impact momentum residual (an error when the run had no impact).
    MaxMomentumResidual,
    /// Normal impulse Λ of the n-th impact (1-based).
    Impulse { n: usize },
    /// Relative excess Λ / (m_tip·|v_n⁻|) − 1 of the n-th impulse over the tip-mass momentum
    /// limit, v_n⁻ the tip's normal velocity just before that impact (both read off the run).
    /// It vanishes as the beam is refined: an instantaneous point impact stops the tip mass
    /// alone.
    ImpulseExcess { n: usize, tip_mass: f64 },
    /// Time of the n-th impact.
    ImpactTime { n: usize },
    /// Time of the n-th release (normal force through zero).
    ReleaseTime { n: usize },
    /// Start (first contact) or end (last release) of the n-th contact episode, where contact
    /// phases separated by a free flight shorter than `min_flight` seconds (micro-bounces) belong
    /// to one episode. Unlike `impact_timeN`, this does not depend on how many micro-bounces a
    /// resolution produces.
    Episode {
        n: usize,
        min_flight: f64,
        end: bool,
    },
}

/// Number of modes requested from a backend for frequency checks up to mode `n`.
pub fn mode_count(n: usize) -> usize {
    n.max(12)
}

/// Which backend analysis a quantity needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Analysis {
    Modes,
    Statics,
    Simulate,
}

impl Quantity {
    /// Parses the grammar of `data::cases` against a scene (aliases resolve to its last link).
    pub fn parse(text: &str, scene: &Scene) -> Result<Quantity, String> {
        let t = text.trim();
        let chain = scene.planar_chain();
        // Outside a planar chain the aliases name link 1 (the payload link is one link).
        let last = chain.map_or(1, |c| c.links.len().max(1));
        let alias = |c: &str| -> String {
            match c {
                "tip_deflection" => channel::tip_deflection(last),
                "tip_x" => channel::tip_x(last),
                "tip_y" => channel::tip_y(last),
                "tip_axial" => channel::tip_axial(last),
                "hub_angle" => channel::joint_angle(1),
                "hub_torque" => channel::joint_torque(1),
                other => other.to_string(),
            }
        };
        let freq = |rest: &str, kind: Option<&str>| -> Result<Quantity, String> {
            let n: usize = rest
                .parse()
                .map_err(|_| format!("`{text}`: expected a mode number after `freq`"))?;
            if n == 0 {
                return Err(format!("`{text}`: modes are numbered from 1"));
            }
            Ok(Quantity::Frequency {
                n,
                kind: kind.map(str::to_string),
            })
        };
        let nth = |rest: &str, what: &str| -> Result<usize, String> {
            match rest.parse::<usize>() {
                Ok(n) if n >= 1 => Ok(n),
                _ => Err(format!(
                    "`{text}`: expected the number (from 1) of the {what} after the name"
                )),
            }
        };
        for (prefix, end) in [("episode_start", false), ("episode_end", true)] {
            if let Some(rest) = t.strip_prefix(prefix) {
                let (num, flight) = rest.split_once(':').ok_or_else(|| {
                    format!(
                        "`{text}`: expected {prefix}N:F (F = shortest free flight, in seconds, \
                         that separates two contact episodes)"
                    )
                })?;
                let min_flight: f64 = flight
                    .parse()
                    .map_err(|_| format!("`{text}`: `{flight}` is not a duration"))?;
                if !(min_flight.is_finite() && min_flight > 0.0) {
                    return Err(format!(
                        "`{text}`: the flight duration must be finite and > 0"
                    ));
                }
                return Ok(Quantity::Episode {
                    n: nth(num, "contact episode")?,
                    min_flight,
                    end,
                });
            }
        }
        if let Some(rest) = t.strip_prefix("impact_time") {
            return Ok(Quantity::ImpactTime {
                n: nth(rest, "impact")?,
            });
        }
        if let Some(rest) = t.strip_prefix("release_time") {
            return Ok(Quantity::ReleaseTime {
                n: nth(rest, "release")?,
            });
        }
        if let Some(rest) = t.strip_prefix("impulse_excess") {
            let link = chain
                .and_then(|c| {
                    let contact = c.contacts.first()?;
                    c.links.get(c.link_index(&contact.link)?)
                })
                .ok_or_else(|| format!("`{text}` needs a scene with a contact"))?;
            let tip_mass = link.tip_mass.filter(|m| *m > 0.0).ok_or_else(|| {
                format!(
                    "`{text}` needs a tip mass on the contact link `{}`",
                    link.name
                )
            })?;
            return Ok(Quantity::ImpulseExcess {
                n: nth(rest, "impact")?,
                tip_mass,
            });
        }
        if let Some(rest) = t.strip_prefix("impulse") {
            return Ok(Quantity::Impulse {
                n: nth(rest, "impact")?,
            });
        }
        if let Some(rest) = t.strip_prefix("axial_freq") {
            return freq(rest, Some("axial"));
        }
        if let Some(rest) = t.strip_prefix("bending_freq") {
            return freq(rest, Some("bending"));
        }
        if let Some(rest) = t.strip_prefix("freq") {
            return freq(rest, None);
        }
        // KIND_freqN for the other mode kinds a backend reports (the 3-D link's
        // `bending-horizontal`, `bending-vertical`, `torsion`).
        if let Some((kind, rest)) = t.split_once("_freq")
            && !kind.is_empty()
            && kind.chars().all(|c| c.is_ascii_lowercase() || c == '-')
        {
            return freq(rest, Some(kind));
        }
        match t {
            "tip_static" => return Ok(Quantity::StaticTip),
            "ledger_closure" => return Ok(Quantity::LedgerClosure),
            "max_momentum_residual" => return Ok(Quantity::MaxMomentumResidual),
            _ => {}
        }
        if let Some(c) = t.strip_prefix("history:") {
            return Ok(Quantity::History {
                channel: alias(c),
                lowpass_hz: None,
            });
        }
        if let Some(rest) = t.strip_prefix("lowpass") {
            let (hz, c) = rest
                .split_once(":history:")
                .ok_or_else(|| format!("`{text}`: expected lowpassF:history:CHANNEL (F in Hz)"))?;
            let f: f64 = hz
                .parse()
                .map_err(|_| format!("`{text}`: `{hz}` is not a cut-off frequency in Hz"))?;
            if !(f.is_finite() && f > 0.0) {
                return Err(format!("`{text}`: the cut-off must be finite and > 0 Hz"));
            }
            return Ok(Quantity::History {
                channel: alias(c),
                lowpass_hz: Some(f),
            });
        }
        if let Some(c) = t.strip_prefix("peak:") {
            return Ok(Quantity::Peak { channel: alias(c) });
        }
        if let Some((c, time)) = t.split_once('@') {
            // `link1.v@3` is a field channel name, not a time: only split on a float time when
            // the channel part is not a field station.
            let tv: f64 = time
                .parse()
                .map_err(|_| format!("`{text}`: `{time}` is not a time"))?;
            if !tv.is_finite() || tv < 0.0 {
                return Err(format!("`{text}`: time must be finite and ≥ 0"));
            }
            return Ok(Quantity::At {
                channel: alias(c),
                t: tv,
            });
        }
        Err(format!(
            "unknown quantity `{text}`; expected freqN, KIND_freqN (axial, bending, \
             bending-horizontal, bending-vertical, torsion), tip_static, \
             CHANNEL@T, peak:CHANNEL, history:CHANNEL, lowpassF:history:CHANNEL, ledger_closure, max_momentum_residual, \
             impulseN, impulse_excessN, impact_timeN, release_timeN, episode_startN:F or episode_endN:F"
        ))
    }

    /// Modes to request from a backend (0 for non-modal quantities).
    pub fn modes_needed(&self) -> usize {
        match self {
            Quantity::Frequency { n, kind: None } => mode_count(*n),
            // The n-th mode of one kind can sit far up the spectrum (the 3-D link's first axial
            // mode is its ~15th): ask for enough modes that every field has n of its own.
            Quantity::Frequency { n, kind: Some(_) } => 4 * mode_count(*n),
            _ => 0,
        }
    }

    pub fn analysis(&self) -> Analysis {
        match self {
            Quantity::Frequency { .. } => Analysis::Modes,
            Quantity::StaticTip => Analysis::Statics,
            _ => Analysis::Simulate,
        }
    }

    pub fn from_modes(&self, r: &ModalResult) -> Result<f64, String> {
        let Quantity::Frequency { n, kind } = self else {
            return Err("not a frequency".into());
        };
        let picked: Vec<f64> = match kind {
            None => r.frequencies_hz.clone(),
            Some(k) => r
                .frequencies_hz
                .iter()
                .zip(&r.kinds)
                // A parenthetical qualifier ("bending-horizontal (no gyroscopic)") keeps the kind.
                .filter(|(_, kk)| {
                    *kk == k
                        || kk
                            .strip_prefix(k.as_str())
                            .is_some_and(|r| r.starts_with(" ("))
                })
                .map(|(f, _)| *f)
                .collect(),
        };
        picked.get(n - 1).copied().ok_or_else(|| {
            format!(
                "the backend returned {} {}frequencies, mode {n} was asked for",
                picked.len(),
                kind.as_ref().map_or(String::new(), |k| format!("{k} "))
            )
        })
    }

    pub fn from_statics(&self, r: &StaticResult) -> Result<f64, String> {
        Ok(r.tip_deflection)
    }

    pub fn from_run(&self, r: &RunResult) -> Result<f64, String> {
        let missing = |c: &str| {
            if c.starts_with(data::cases::ENERGY_PREFIX) {
                let l = &r.ledger;
                let terms: Vec<String> = l
                    .stored
                    .iter()
                    .chain(&l.inputs)
                    .chain(&l.dissipation)
                    .map(|t| format!("energy.{}", t.name))
                    .collect();
                return format!(
                    "no ledger term `{c}` in the run; available: energy.total, {} (sums as energy.A+B)",
                    terms.join(", ")
                );
            }
            let names: Vec<&str> = r
                .observables
                .channels
                .iter()
                .map(|c| c.name.as_str())
                .filter(|n| !n.contains('@'))
                .collect();
            let payload_run = r.observables.get(data::channel::PAYLOAD_X).is_some();
            match data::channel::payload_link_field_of(c) {
                Some(field) if payload_run => format!(
                    "no channel `{c}` in the run: the scene's rod does not carry the {} field \
                     (a 3-D link writes the channels of its carried fields only); available: {}",
                    field.name(),
                    names.join(", ")
                ),
                _ => format!(
                    "no channel `{c}` in the run; available: {}",
                    names.join(", ")
                ),
            }
        };
        match self {
            Quantity::At { channel, t } => {
                let (times, values) =
                    super::history::series(r, channel).ok_or_else(|| missing(channel))?;
                data::results::interpolate(times, &values, *t).ok_or_else(|| {
                    format!(
                        "t = {t} is outside the run [0, {}]",
                        times.last().copied().unwrap_or(0.0)
                    )
                })
            }
            Quantity::Peak { channel } | Quantity::History { channel, .. } => {
                let (_, values) =
                    super::history::series(r, channel).ok_or_else(|| missing(channel))?;
                Ok(values.iter().fold(0.0f64, |m, v| m.max(v.abs())))
            }
            Quantity::LedgerClosure => Ok(r.ledger.relative_closure()),
            Quantity::MaxMomentumResidual => {
                let residuals: Vec<f64> = r
                    .events
                    .iter()
                    .filter_map(|e| match e {
                        data::Event::Impact {
                            momentum_residual, ..
                        } => Some(*momentum_residual),
                        _ => None,
                    })
                    .collect();
                if residuals.is_empty() {
                    return Err("the run had no impact: no momentum balance to check".into());
                }
                Ok(residuals.into_iter().fold(0.0, f64::max))
            }
            Quantity::ImpulseExcess { n, tip_mass } => {
                let (impulse, v_before) = r
                    .events
                    .iter()
                    .filter_map(|e| match e {
                        data::Event::Impact {
                            impulse,
                            normal_velocity_before,
                            ..
                        } => Some((*impulse, *normal_velocity_before)),
                        _ => None,
                    })
                    .nth(*n - 1)
                    .ok_or_else(|| format!("impact {n} was asked for; the run had fewer"))?;
                let limit = tip_mass * v_before.abs();
                if limit.is_nan() || limit <= 0.0 {
                    return Err(format!(
                        "impact {n} has no approach velocity (v_n⁻ = {v_before:e})"
                    ));
                }
                Ok(impulse / limit - 1.0)
            }
            Quantity::Impulse { n } | Quantity::ImpactTime { n } => {
                let impacts: Vec<(f64, f64)> = r
                    .events
                    .iter()
                    .filter_map(|e| match e {
                        data::Event::Impact { t, impulse, .. } => Some((*t, *impulse)),
                        _ => None,
                    })
                    .collect();
                let (t, impulse) = impacts.get(n - 1).copied().ok_or_else(|| {
                    format!("impact {n} was asked for; the run had {}", impacts.len())
                })?;
                Ok(if matches!(self, Quantity::Impulse { .. }) {
                    impulse
                } else {
                    t
                })
            }
            Quantity::ReleaseTime { n } => {
                let releases: Vec<f64> = r
                    .events
                    .iter()
                    .filter_map(|e| match e {
                        data::Event::Release { t, .. } => Some(*t),
                        _ => None,
                    })
                    .collect();
                releases.get(n - 1).copied().ok_or_else(|| {
                    format!("release {n} was asked for; the run had {}", releases.len())
                })
            }
            Quantity::Episode { n, min_flight, end } => {
                let episodes = data::results::contact_episodes(&r.events, *min_flight);
                let (start, stop) = episodes.get(n - 1).copied().ok_or_else(|| {
                    format!(
                        "contact episode {n} was asked for; the run had {} (free flights \
                         shorter than {min_flight} s merged)",
                        episodes.len()
                    )
                })?;
                if !*end {
                    return Ok(start);
                }
                stop.ok_or_else(|| format!("contact episode {n} lasts to the end of the run"))
            }
            _ => Err("not a run quantity".into()),
        }
    }

    /// Scale of the reference time history for `relative-to-peak` norms.
    pub fn peak_scale(&self, r: &RunResult) -> Option<f64> {
        match self {
            Quantity::At { channel, .. }
            | Quantity::Peak { channel }
            | Quantity::History { channel, .. } => super::history::series(r, channel)
                .map(|(_, v)| v.iter().fold(0.0f64, |m, v| m.max(v.abs()))),
            _ => None,
        }
    }
}
