//! Reading and checking wind files: a field's bad value located at its line, and the ranges
//! every field's values must lie in.

use super::*;

/// The first error inside a `[[field]]` table, located at its value. Serde reads a tagged
/// table whole before its fields, so the parser can only point at the table; here each
/// table is read again on its own as the struct its `kind` names, with every other line
/// blanked (offsets kept), which locates the value. Read on its own, a fixed-size array
/// ignores extra elements that the tagged read refuses: those are compared too. `None`
/// when every table reads.
pub(super) fn field_table_error(text: &str) -> Option<(usize, usize, String)> {
    fn first_error<T: serde::de::DeserializeOwned + Serialize>(doc: &str) -> Option<(usize, usize, String)> {
        let read = match toml::from_str::<T>(doc) {
            Ok(read) => read,
            Err(e) => return Some(crate::io::toml_error(doc, &e)),
        };
        let (raw, read) = (toml::from_str::<toml::Table>(doc).ok()?, toml::Table::try_from(&read).ok()?);
        raw.iter().find_map(|(key, v)| {
            let (n, m) = (v.as_array()?.len(), read.get(key)?.as_array()?.len());
            (n != m).then(|| {
                let at = doc.lines().position(|l| l.split('=').next().is_some_and(|k| k.trim() == key))?;
                let column = doc.lines().nth(at)?.find('[')? + 1;
                Some((at + 1, column, format!("invalid length {n}, expected {m} elements (key `{key}`)")))
            })?
        })
    }
    let lines: Vec<&str> = text.split_inclusive('\n').collect();
    let mut k = 0;
    while k < lines.len() {
        if lines[k].trim() != "[[field]]" {
            k += 1;
            continue;
        }
        let end = (k + 1..lines.len()).find(|&j| lines[j].trim_start().starts_with('[')).unwrap_or(lines.len());
        let blank = |l: &str| l.chars().map(|c| if c == '\n' { '\n' } else { ' ' }).collect::<String>();
        let mut kind = None;
        let doc: String = lines
            .iter()
            .enumerate()
            .map(|(j, l)| {
                let key = l.split('=').next().unwrap_or("").trim();
                if (k + 1..end).contains(&j) && key == "kind" {
                    kind = l.split('"').nth(1).map(str::to_string);
                    blank(l)
                } else if (k + 1..end).contains(&j) {
                    l.to_string()
                } else {
                    blank(l)
                }
            })
            .collect();
        let found = match kind.as_deref() {
            Some("constant") => first_error::<Constant>(&doc),
            Some("sum_of_sines") => first_error::<SumOfSines>(&doc),
            Some("gust_front") => first_error::<GustFront>(&doc),
            Some("vortex") => first_error::<Vortex>(&doc),
            Some("blast") => first_error::<Blast>(&doc),
            Some("turbulence") => first_error::<Turbulence>(&doc),
            Some("grid") => first_error::<Grid>(&doc),
            _ => None,
        };
        if found.is_some() {
            return found;
        }
        k = end;
    }
    None
}

impl WindScene {
    /// Checks ranges: (field index, field name, message) of the first bad value; a wave's
    /// values are named with their index (`waves[2].speed`).
    pub fn check(&self) -> Result<(), (usize, String, String)> {
        for (i, f) in self.fields.iter().enumerate() {
            let mut vals: Vec<(String, f32, f32, f32)> = Vec::new(); // name, value, min, max
            let named = |vals: &mut Vec<(String, f32, f32, f32)>, list: &[(&str, f32, f32, f32)]| {
                vals.extend(list.iter().map(|&(n, v, lo, hi)| (n.to_string(), v, lo, hi)));
            };
            let fades = |vals: &mut Vec<(String, f32, f32, f32)>, fade_in: Option<Fade>, fade_out: Option<Fade>| {
                for (name, f) in [("fade_in", fade_in), ("fade_out", fade_out)] {
                    if let Some(f) = f {
                        vals.push((format!("{name}.start"), f.start, -1e7, 1e7));
                        vals.push((format!("{name}.duration"), f.duration, 1e-3, 1e7));
                    }
                }
            };
            match f {
                WindField::Constant(c) => {
                    named(&mut vals, &[("speed", c.speed, -1e3, 1e3)]);
                    for v in c.direction {
                        named(&mut vals, &[("direction", v, -1e6, 1e6)]);
                    }
                    if c.direction.iter().all(|v| *v == 0.0) && c.speed != 0.0 {
                        return Err((i, "direction".into(), "must not be the zero vector".into()));
                    }
                }
                WindField::SumOfSines(s) => {
                    if s.waves.len() > MAX_WAVES as usize {
                        return Err((i, "waves".into(), format!("{} waves, at most {MAX_WAVES}", s.waves.len())));
                    }
                    if let Some(k) = s.sharpness {
                        named(&mut vals, &[("sharpness", k, 1e-3, 100.0)]);
                    }
                    fades(&mut vals, s.fade_in, s.fade_out);
                    for (k, w) in s.waves.iter().enumerate() {
                        for (n, v, lo, hi) in [
                            ("amplitude", w.amplitude, -1e3, 1e3),
                            ("direction_deg", w.direction_deg, -1e4, 1e4),
                            ("wavelength", w.wavelength, 1e-3, 1e7),
                            ("speed", w.speed, -1e4, 1e4),
                        ] {
                            vals.push((format!("waves[{k}].{n}"), v, lo, hi));
                        }
                    }
                }
                WindField::GustFront(g) => named(
                    &mut vals,
                    &[
                        ("origin", g.origin[0], -1e7, 1e7),
                        ("origin", g.origin[1], -1e7, 1e7),
                        ("direction_deg", g.direction_deg, -1e4, 1e4),
                        ("strength", g.strength, -1e3, 1e3),
                        ("speed", g.speed, 0.0, 1e4),
                        ("width", g.width, 1e-3, 1e7),
                        ("length", g.length, 1e-3, 1e7),
                        ("radius", g.radius, 1e-3, 1e7),
                        ("start", g.start, -1e7, 1e7),
                    ],
                ),
                WindField::Vortex(v) => named(
                    &mut vals,
                    &[
                        ("centre", v.centre[0], -1e7, 1e7),
                        ("centre", v.centre[1], -1e7, 1e7),
                        ("drift", v.drift[0], -1e4, 1e4),
                        ("drift", v.drift[1], -1e4, 1e4),
                        ("strength", v.strength, -1e3, 1e3),
                        ("radius", v.radius, 1e-3, 1e7),
                        ("updraft", v.updraft, -1e3, 1e3),
                        ("start", v.start, -1e7, 1e7),
                        ("duration", v.duration, 0.0, 1e9),
                        ("fade", v.fade, 1e-3, 1e9),
                    ],
                ),
                WindField::Blast(b) => named(
                    &mut vals,
                    &[
                        ("centre", b.centre[0], -1e7, 1e7),
                        ("centre", b.centre[1], -1e7, 1e7),
                        ("centre", b.centre[2], -1e7, 1e7),
                        ("strength", b.strength, -1e4, 1e4),
                        ("start", b.start, -1e7, 1e7),
                        ("speed", b.speed, 0.0, 1e5),
                        ("width", b.width, 1e-3, 1e7),
                        ("decay", b.decay, 1e-3, 1e9),
                        ("radius", b.radius, 1e-3, 1e7),
                    ],
                ),
                WindField::Turbulence(t) => {
                    if t.components == 0 || t.components > MAX_WAVES {
                        return Err((i, "components".into(), format!("{} is outside [1, {MAX_WAVES}]", t.components)));
                    }
                    named(
                        &mut vals,
                        &[
                            ("intensity", t.intensity, 0.0, 1e3),
                            ("beta", t.beta, 0.0, 4.0),
                            ("f_min", t.f_min, 1e-5, 1e3),
                            ("f_max", t.f_max, 1e-5, 1e3),
                            ("mean_speed", t.mean_speed, 1e-2, 1e3),
                            ("vertical", t.vertical, 0.0, 10.0),
                        ],
                    );
                    if let Some(d) = t.direction_deg {
                        named(&mut vals, &[("direction_deg", d, -1e4, 1e4)]);
                    }
                    fades(&mut vals, t.fade_in, t.fade_out);
                    // Related only once each is in range (a non-finite or huge one is named).
                    let in_range = |f: f32| (1e-5..=1e3).contains(&f);
                    if in_range(t.f_min) && in_range(t.f_max) && t.f_max <= t.f_min {
                        return Err((i, "f_max".into(), format!("{} must be above f_min ({})", t.f_max, t.f_min)));
                    }
                }
                WindField::Grid(g) => {
                    for (name, v, lo, hi) in
                        [("cell", g.cell, 1e-3, 1e6), ("origin", g.origin, -1e7, 1e7), ("scroll", g.scroll, -1e3, 1e3)]
                    {
                        named(&mut vals, &v.map(|v| (name, v, lo, hi)));
                    }
                    named(&mut vals, &[("frame_rate", g.frame_rate, 0.0, 1e4), ("scale", g.scale, -1e3, 1e3)]);
                    if let Some(r) = g.range {
                        named(&mut vals, &[("range", r, 1e-3, 1e3)]);
                    }
                    if let Some(n) = g.frames.filter(|n| !(1..=grid::MAX_GRID_SIDE).contains(n)) {
                        return Err((i, "frames".into(), format!("{n} is outside [1, {}]", grid::MAX_GRID_SIDE)));
                    }
                }
            }
            for (name, v, lo, hi) in vals {
                if !v.is_finite() {
                    return Err((i, name, format!("{v} is not a finite number")));
                }
                if v < lo || v > hi {
                    return Err((i, name, format!("{v} is outside [{lo}, {hi}]")));
                }
            }
        }
        Ok(())
    }
}
