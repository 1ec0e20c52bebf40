//! Scripted input (`sylva view --script FILE`), for tests and demos: one command per line,
//! `#` starts a comment.
//!
//! ```text
//! frames 10            # run 10 frames (1/60 s of simulation each, times the time scale)
//! click 0.5 0.8        # click the view at (u, v), 0…1 from its top left, with the tool
//! tool blast|vortex    # what a click places
//! blast 3.0 -2.0       # a blast at ground point (x, z)
//! wind 90 12           # a constant extra wind: direction (degrees from +X toward +Z), m/s
//! method 0 akagi       # tree 0's method (rebuilds it)
//! forest 0 1000        # tree 0 as a forest of 1,000 instances
//! overwrite-scene F    # copy F over the scene file (as an editor would), for hot reload
//! screenshot out.png   # the 3D view as a PNG
//! report out.json      # frames, time, stage times, every tree's displacement, reload status
//! quit
//! ```

use anyhow::{Context, Result, bail};
use std::path::PathBuf;

/// One scripted input.
#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    /// Run this many frames.
    Frames(u32),
    /// Click the 3D view at (u, v).
    Click(f32, f32),
    /// Choose what a click places.
    Tool(Tool),
    /// A blast at ground point (x, z).
    Blast(f32, f32),
    /// A constant extra wind: direction, degrees; speed, m/s.
    Wind(f32, f32),
    /// Set a tree's method.
    Method(usize, String),
    /// Make a tree a forest of this many instances.
    Forest(usize, usize),
    /// Copy a file over the scene file.
    OverwriteScene(PathBuf),
    /// Save the 3D view.
    Screenshot(PathBuf),
    /// Write a JSON report.
    Report(PathBuf),
    /// Close the window.
    Quit,
}

/// What a click in the view places.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Tool {
    /// An explosion: a shell of outward wind (Zioma's local effect).
    #[default]
    Blast,
    /// A whirlwind turning about a vertical axis.
    Vortex,
    /// A gust along a drag (dragging with this tool pushes instead of orbiting).
    Push,
    /// Nothing: clicks only select.
    None,
}

/// Parses a script; errors name the file, line and what was expected.
pub fn parse_script(text: &str, file: &str) -> Result<Vec<Command>> {
    let mut out = Vec::new();
    for (n, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let words: Vec<&str> = line.split_whitespace().collect();
        let at = || format!("{file}:{}", n + 1);
        let num = |k: usize| -> Result<f32> {
            let w =
                words.get(k).with_context(|| format!("{}: `{line}`: expected a number after `{}`", at(), words[0]))?;
            let v: f32 = w.parse().map_err(|_| anyhow::anyhow!("{}: `{w}` is not a number", at()))?;
            if !v.is_finite() {
                bail!("{}: `{w}`: expected a finite number", at());
            }
            Ok(v)
        };
        let arity = |k: usize| -> Result<()> {
            if words.len() != k + 1 {
                bail!("{}: `{line}`: `{}` takes {k} argument(s)", at(), words[0]);
            }
            Ok(())
        };
        let cmd = match words[0] {
            "frames" => {
                arity(1)?;
                let v = num(1)?;
                if !(0.0..=1e6).contains(&v) || v.fract() != 0.0 {
                    bail!("{}: `{line}`: expected a whole number of frames, 0 to 1,000,000", at());
                }
                Command::Frames(v as u32)
            }
            "click" => {
                arity(2)?;
                let (u, v) = (num(1)?, num(2)?);
                if !((0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v)) {
                    bail!("{}: `{line}`: expected view coordinates from 0 to 1", at());
                }
                Command::Click(u, v)
            }
            "tool" => {
                arity(1)?;
                Command::Tool(match words[1] {
                    "blast" => Tool::Blast,
                    "vortex" => Tool::Vortex,
                    "push" => Tool::Push,
                    "none" => Tool::None,
                    w => bail!("{}: tool `{w}`: expected blast, vortex, push or none", at()),
                })
            }
            "blast" => {
                arity(2)?;
                Command::Blast(num(1)?, num(2)?)
            }
            "wind" => {
                arity(2)?;
                let speed = num(2)?;
                if !(0.0..=100.0).contains(&speed) {
                    bail!("{}: `{line}`: expected a speed from 0 to 100 m/s", at());
                }
                Command::Wind(num(1)?, speed)
            }
            "method" => {
                arity(2)?;
                let tree =
                    words[1].parse().map_err(|_| anyhow::anyhow!("{}: `{}` is not a tree index", at(), words[1]))?;
                let m = words[2];
                if !m.chars().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_') {
                    bail!("{}: method `{m}`: expected a method's name (zioma, akagi, skjermo, hsm, …)", at());
                }
                Command::Method(tree, m.to_string())
            }
            "forest" => {
                arity(2)?;
                let parse =
                    |w: &str| w.parse::<usize>().map_err(|_| anyhow::anyhow!("{}: `{w}` is not a whole number", at()));
                let (tree, n) = (parse(words[1])?, parse(words[2])?);
                if !(1..=100_000).contains(&n) {
                    bail!("{}: `{line}`: expected 1 to 100,000 instances", at());
                }
                Command::Forest(tree, n)
            }
            "overwrite-scene" => {
                arity(1)?;
                Command::OverwriteScene(words[1].into())
            }
            "screenshot" => {
                arity(1)?;
                Command::Screenshot(words[1].into())
            }
            "report" => {
                arity(1)?;
                Command::Report(words[1].into())
            }
            "quit" => {
                arity(0)?;
                Command::Quit
            }
            w => bail!(
                "{}: unknown command `{w}`: expected frames, click, tool, blast, wind, method, forest, overwrite-scene, screenshot, report or quit",
                at()
            ),
        };
        out.push(cmd);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scripts_parse_and_bad_lines_name_file_and_line() {
        let s = parse_script("frames 3\n# comment\nclick 0.5 0.25 # trailing\ntool vortex\nquit\n", "s.txt").unwrap();
        assert_eq!(s, [Command::Frames(3), Command::Click(0.5, 0.25), Command::Tool(Tool::Vortex), Command::Quit]);
        for (bad, want) in [
            ("frames x", "s.txt:1"),
            ("frames 2.5", "whole number"),
            ("click 2 0", "0 to 1"),
            ("wobble", "unknown command `wobble`"),
            ("tool hammer", "blast, vortex, push or none"),
            ("forest 0 0", "1 to 100,000"),
            ("method 0 Tele-port", "zioma, akagi"),
            ("quit now", "takes 0"),
        ] {
            let e = parse_script(bad, "s.txt").unwrap_err().to_string();
            assert!(e.contains(want) && e.contains("s.txt:1"), "{bad}: {e}");
        }
    }
}
