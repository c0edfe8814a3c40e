//! What the user can ask of the viewer. Mouse and keyboard input and the hidden test script
//! both become [`Action`]s, handled by one function, so tests drive the same code as users.

use std::collections::BTreeMap;

#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    /// Drag in window pixels (x right, y down).
    Orbit {
        dx: f32,
        dy: f32,
    },
    Pan {
        dx: f32,
        dy: f32,
    },
    /// Wheel steps; positive moves towards the target.
    Dolly {
        steps: f32,
    },
    /// Translation in eye–target distances along image-right, up and the view direction.
    Fly {
        right: f32,
        up: f32,
        forward: f32,
    },
    /// Forget the samples and start again.
    Restart,
    /// Add stops to the display exposure.
    Exposure {
        stops: f32,
    },
    /// Save what is shown as a PNG in the working directory.
    SavePng,
    /// Save the linear mean radiance as an EXR.
    SaveExr,
    /// Turn denoising of the shown image on or off (D).
    Denoise,
    /// Switch between path tracing and bidirectional path tracing (I).
    SwitchIntegrator,
    /// Re-read the scene file now.
    Reload,
    /// Ask the window system for a new inner size (tests: the same path as a user resize).
    Resize {
        width: u32,
        height: u32,
    },
    /// Tests only: block until the running background denoise finishes (at most 60 s), so a
    /// test sees a denoised image land at a known frame.
    WaitForDenoise,
    /// Tests only: block until the scene file changes (at most 60 s), so a test can edit the
    /// file at a known frame instead of racing the frame counter.
    WaitForEdit,
    Quit,
}

/// Actions to run before given frames (0-based), from the hidden `--script` flag:
/// `"5:orbit 40 0; 10:reload; 12:quit"`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Script {
    at_frame: BTreeMap<u64, Vec<Action>>,
}

impl Script {
    pub fn parse(text: &str) -> Result<Script, String> {
        let mut script = Script::default();
        for item in text.split(';').map(str::trim).filter(|s| !s.is_empty()) {
            let (frame, command) = item
                .split_once(':')
                .ok_or_else(|| format!("{item:?}: expected FRAME:ACTION"))?;
            let frame: u64 = frame
                .trim()
                .parse()
                .map_err(|_| format!("{item:?}: {frame:?} is not a frame number"))?;
            let action = parse_action(command).map_err(|e| format!("{item:?}: {e}"))?;
            script.at_frame.entry(frame).or_default().push(action);
        }
        Ok(script)
    }

    /// The actions due before `frame`, removed from the script.
    pub fn take(&mut self, frame: u64) -> Vec<Action> {
        self.at_frame.remove(&frame).unwrap_or_default()
    }
}

fn parse_action(command: &str) -> Result<Action, String> {
    let words: Vec<&str> = command.split_whitespace().collect();
    let (&name, args) = words.split_first().ok_or("empty action")?;
    let numbers = |n: usize| -> Result<Vec<f32>, String> {
        if args.len() != n {
            return Err(format!("{name} takes {n} numbers"));
        }
        args.iter()
            .map(|a| {
                a.parse::<f32>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| format!("{a:?} is not a number"))
            })
            .collect()
    };
    Ok(match name {
        "orbit" => {
            let v = numbers(2)?;
            Action::Orbit { dx: v[0], dy: v[1] }
        }
        "pan" => {
            let v = numbers(2)?;
            Action::Pan { dx: v[0], dy: v[1] }
        }
        "dolly" => Action::Dolly {
            steps: numbers(1)?[0],
        },
        "fly" => {
            let v = numbers(3)?;
            Action::Fly {
                right: v[0],
                up: v[1],
                forward: v[2],
            }
        }
        "exposure" => Action::Exposure {
            stops: numbers(1)?[0],
        },
        "resize" => {
            let v = numbers(2)?;
            if v.iter().any(|x| !(1.0..=16384.0).contains(x)) {
                return Err("resize takes two sizes in 1..=16384".into());
            }
            Action::Resize {
                width: v[0] as u32,
                height: v[1] as u32,
            }
        }
        _ if !args.is_empty() => return Err(format!("{name} takes no arguments")),
        "restart" => Action::Restart,
        "save-png" => Action::SavePng,
        "save-exr" => Action::SaveExr,
        "reload" => Action::Reload,
        "wait-edit" => Action::WaitForEdit,
        "denoise" => Action::Denoise,
        "integrator" => Action::SwitchIntegrator,
        "wait-denoised" => Action::WaitForDenoise,
        "quit" => Action::Quit,
        _ => return Err(format!("unknown action {name:?}")),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_a_script_in_frame_order() {
        let mut s = Script::parse(" 5:orbit 40 -2.5; 10:reload;5:restart ;12: quit ;").unwrap();
        assert_eq!(s.take(0), vec![]);
        assert_eq!(
            s.take(5),
            vec![Action::Orbit { dx: 40.0, dy: -2.5 }, Action::Restart]
        );
        assert_eq!(s.take(5), vec![], "taken actions are gone");
        assert_eq!(s.take(10), vec![Action::Reload]);
        assert_eq!(s.take(12), vec![Action::Quit]);
        assert_eq!(
            Script::parse("0:denoise; 0:wait-denoised; 0:integrator")
                .unwrap()
                .take(0),
            vec![
                Action::Denoise,
                Action::WaitForDenoise,
                Action::SwitchIntegrator
            ]
        );
        assert_eq!(
            Script::parse("1:fly 0 0 0.5; 2:resize 64 32; 3:exposure -1")
                .unwrap()
                .take(2),
            vec![Action::Resize {
                width: 64,
                height: 32
            }]
        );
    }

    #[test]
    fn rejects_bad_scripts_with_a_reason() {
        for (bad, reason) in [
            ("orbit 1 2", "FRAME:ACTION"),
            ("x:quit", "frame number"),
            ("1:spin", "unknown action"),
            ("1:orbit 1", "takes 2 numbers"),
            ("1:orbit 1 nan", "not a number"),
            ("1:quit now", "no arguments"),
            ("1:resize 0 10", "sizes"),
            ("1:", "empty"),
        ] {
            let e = Script::parse(bad).unwrap_err();
            assert!(e.contains(reason), "{bad}: {e}");
        }
    }
}
