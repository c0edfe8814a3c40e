//! Mouse and keyboard state → [`Action`]s. Drags become orbit or pan deltas; fly keys are
//! held, so they become one fly step per frame scaled by the frame's duration (the speed does
//! not depend on the frame rate or the keyboard's repeat rate).

use super::action::Action;
use std::collections::BTreeSet;
use std::time::Duration;
use winit::event::{ElementState, MouseButton, MouseScrollDelta};
use winit::keyboard::{Key, KeyCode, NamedKey, PhysicalKey};

/// Fly speed in eye–target distances per second.
pub const FLY_SPEED: f32 = 0.5;
/// Pixels of a touchpad's pixel-precise scroll that count as one wheel step.
const PIXELS_PER_WHEEL_STEP: f32 = 50.0;

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum FlyKey {
    Forward,
    Back,
    Left,
    Right,
    Down,
    Up,
}

#[derive(Default)]
pub struct InputState {
    orbiting: bool,
    panning: bool,
    cursor: Option<(f64, f64)>,
    flying: BTreeSet<FlyKey>,
}

impl InputState {
    pub fn mouse_button(&mut self, button: MouseButton, state: ElementState) {
        let pressed = state.is_pressed();
        match button {
            MouseButton::Left => self.orbiting = pressed,
            MouseButton::Right | MouseButton::Middle => self.panning = pressed,
            _ => {}
        }
    }

    /// A drag while a button is held; the first position after a jump (cursor entering the
    /// window) only sets the reference point.
    pub fn cursor_moved(&mut self, x: f64, y: f64) -> Option<Action> {
        let last = self.cursor.replace((x, y))?;
        let (dx, dy) = ((x - last.0) as f32, (y - last.1) as f32);
        if dx == 0.0 && dy == 0.0 {
            return None;
        }
        if self.orbiting {
            Some(Action::Orbit { dx, dy })
        } else if self.panning {
            Some(Action::Pan { dx, dy })
        } else {
            None
        }
    }

    pub fn cursor_left(&mut self) {
        self.cursor = None;
    }

    pub fn wheel(&mut self, delta: MouseScrollDelta) -> Option<Action> {
        let steps = match delta {
            MouseScrollDelta::LineDelta(_, y) => y,
            MouseScrollDelta::PixelDelta(p) => p.y as f32 / PIXELS_PER_WHEEL_STEP,
        };
        (steps != 0.0 && steps.is_finite()).then_some(Action::Dolly { steps })
    }

    /// A key press or release. Fly keys go by their physical position (the arrow keys, and Q
    /// and E where they are on a QWERTY keyboard, on any layout); the others by the character
    /// they type. Returns the action of a press, if any.
    pub fn key(
        &mut self,
        physical: PhysicalKey,
        logical: &Key,
        state: ElementState,
        repeat: bool,
    ) -> Option<Action> {
        // Not WASD: D is the denoiser's key (issue 12), and a WASD without D would send a
        // user's right hand to it; the arrow keys are what every viewer flies with besides.
        let fly = match physical {
            PhysicalKey::Code(KeyCode::ArrowUp) => Some(FlyKey::Forward),
            PhysicalKey::Code(KeyCode::ArrowDown) => Some(FlyKey::Back),
            PhysicalKey::Code(KeyCode::ArrowLeft) => Some(FlyKey::Left),
            PhysicalKey::Code(KeyCode::ArrowRight) => Some(FlyKey::Right),
            PhysicalKey::Code(KeyCode::KeyQ) => Some(FlyKey::Down),
            PhysicalKey::Code(KeyCode::KeyE) => Some(FlyKey::Up),
            _ => None,
        };
        if let Some(k) = fly {
            if state.is_pressed() {
                self.flying.insert(k);
            } else {
                self.flying.remove(&k);
            }
            return None;
        }
        if !state.is_pressed() {
            return None;
        }
        let numpad = match physical {
            PhysicalKey::Code(KeyCode::NumpadAdd) => Some(Action::Exposure { stops: 0.5 }),
            PhysicalKey::Code(KeyCode::NumpadSubtract) => Some(Action::Exposure { stops: -0.5 }),
            _ => None,
        };
        if numpad.is_some() {
            return numpad;
        }
        match logical {
            Key::Named(NamedKey::Escape) if !repeat => Some(Action::Quit),
            Key::Character(c) => match c.as_str() {
                // `=` is `+` without shift on most layouts.
                "+" | "=" => Some(Action::Exposure { stops: 0.5 }),
                "-" | "_" => Some(Action::Exposure { stops: -0.5 }),
                "r" | "R" if !repeat => Some(Action::Restart),
                "p" | "P" if !repeat => Some(Action::SavePng),
                "x" | "X" if !repeat => Some(Action::SaveExr),
                "d" | "D" if !repeat => Some(Action::Denoise),
                "i" | "I" if !repeat => Some(Action::SwitchIntegrator),
                _ => None,
            },
            _ => None,
        }
    }

    /// Keys are released while the window has no focus without us hearing of it.
    pub fn focus_lost(&mut self) {
        self.flying.clear();
        self.orbiting = false;
        self.panning = false;
    }

    /// The fly step for a frame that took `dt`, while fly keys are held.
    pub fn fly_step(&self, dt: Duration) -> Option<Action> {
        let axis = |plus, minus| {
            (self.flying.contains(&plus) as i32 - self.flying.contains(&minus) as i32) as f32
        };
        let (right, up, forward) = (
            axis(FlyKey::Right, FlyKey::Left),
            axis(FlyKey::Up, FlyKey::Down),
            axis(FlyKey::Forward, FlyKey::Back),
        );
        if right == 0.0 && up == 0.0 && forward == 0.0 {
            return None;
        }
        // A long stall (reload, resize) must not fling the camera away.
        let step = FLY_SPEED * dt.as_secs_f32().min(0.1);
        Some(Action::Fly {
            right: right * step,
            up: up * step,
            forward: forward * step,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use winit::dpi::PhysicalPosition;

    const PRESS: ElementState = ElementState::Pressed;
    const RELEASE: ElementState = ElementState::Released;

    fn key(s: &mut InputState, code: KeyCode, text: &str, state: ElementState) -> Option<Action> {
        s.key(
            PhysicalKey::Code(code),
            &Key::Character(text.into()),
            state,
            false,
        )
    }

    fn arrow(s: &mut InputState, code: KeyCode, state: ElementState) -> Option<Action> {
        let name = match code {
            KeyCode::ArrowUp => NamedKey::ArrowUp,
            KeyCode::ArrowDown => NamedKey::ArrowDown,
            KeyCode::ArrowLeft => NamedKey::ArrowLeft,
            _ => NamedKey::ArrowRight,
        };
        s.key(PhysicalKey::Code(code), &Key::Named(name), state, false)
    }

    #[test]
    fn drags_orbit_with_the_left_button_and_pan_with_the_others() {
        let mut s = InputState::default();
        assert_eq!(s.cursor_moved(10.0, 10.0), None);
        assert_eq!(s.cursor_moved(20.0, 10.0), None, "no button, no drag");
        s.mouse_button(MouseButton::Left, PRESS);
        assert_eq!(
            s.cursor_moved(25.0, 7.0),
            Some(Action::Orbit { dx: 5.0, dy: -3.0 })
        );
        s.mouse_button(MouseButton::Left, RELEASE);
        s.mouse_button(MouseButton::Middle, PRESS);
        assert_eq!(
            s.cursor_moved(24.0, 7.0),
            Some(Action::Pan { dx: -1.0, dy: 0.0 })
        );
        s.cursor_left();
        assert_eq!(s.cursor_moved(100.0, 100.0), None, "re-entry is no jump");
    }

    #[test]
    fn wheel_dollies() {
        let mut s = InputState::default();
        assert_eq!(
            s.wheel(MouseScrollDelta::LineDelta(0.0, 2.0)),
            Some(Action::Dolly { steps: 2.0 })
        );
        assert_eq!(
            s.wheel(MouseScrollDelta::PixelDelta(PhysicalPosition::new(
                0.0, -25.0
            ))),
            Some(Action::Dolly { steps: -0.5 })
        );
        assert_eq!(s.wheel(MouseScrollDelta::LineDelta(3.0, 0.0)), None);
    }

    #[test]
    fn held_fly_keys_give_one_step_per_frame() {
        let mut s = InputState::default();
        assert_eq!(s.fly_step(Duration::from_millis(20)), None);
        assert_eq!(arrow(&mut s, KeyCode::ArrowUp, PRESS), None);
        assert_eq!(arrow(&mut s, KeyCode::ArrowRight, PRESS), None);
        key(&mut s, KeyCode::KeyE, "e", PRESS);
        key(&mut s, KeyCode::KeyQ, "q", PRESS);
        let Some(Action::Fly { right, up, forward }) = s.fly_step(Duration::from_millis(20)) else {
            panic!("expected a fly step");
        };
        assert_eq!((right, up), (0.01, 0.0));
        assert_eq!(forward, 0.01);
        arrow(&mut s, KeyCode::ArrowUp, RELEASE);
        arrow(&mut s, KeyCode::ArrowRight, RELEASE);
        key(&mut s, KeyCode::KeyE, "e", RELEASE);
        assert!(matches!(
            s.fly_step(Duration::from_secs(5)),
            Some(Action::Fly { up, .. }) if up == -0.05
        ));
        s.focus_lost();
        assert_eq!(s.fly_step(Duration::from_millis(20)), None);
        arrow(&mut s, KeyCode::ArrowLeft, PRESS);
        arrow(&mut s, KeyCode::ArrowDown, PRESS);
        assert_eq!(
            s.fly_step(Duration::from_millis(20)),
            Some(Action::Fly {
                right: -0.01,
                up: 0.0,
                forward: -0.01
            })
        );
    }

    #[test]
    fn keys_map_to_actions() {
        let mut s = InputState::default();
        assert_eq!(
            key(&mut s, KeyCode::KeyR, "r", PRESS),
            Some(Action::Restart)
        );
        assert_eq!(key(&mut s, KeyCode::KeyR, "r", RELEASE), None);
        assert_eq!(
            key(&mut s, KeyCode::KeyP, "p", PRESS),
            Some(Action::SavePng)
        );
        assert_eq!(
            key(&mut s, KeyCode::KeyX, "x", PRESS),
            Some(Action::SaveExr)
        );
        // D denoises; it is no fly key (fly right is the right arrow).
        assert_eq!(
            key(&mut s, KeyCode::KeyD, "d", PRESS),
            Some(Action::Denoise)
        );
        assert_eq!(s.fly_step(Duration::from_millis(20)), None);
        assert_eq!(key(&mut s, KeyCode::KeyD, "d", RELEASE), None);
        assert_eq!(
            key(&mut s, KeyCode::Equal, "=", PRESS),
            Some(Action::Exposure { stops: 0.5 })
        );
        assert_eq!(
            key(&mut s, KeyCode::Minus, "-", PRESS),
            Some(Action::Exposure { stops: -0.5 })
        );
        assert_eq!(
            s.key(
                PhysicalKey::Code(KeyCode::NumpadAdd),
                &Key::Character("+".into()),
                PRESS,
                false
            ),
            Some(Action::Exposure { stops: 0.5 })
        );
        assert_eq!(
            s.key(
                PhysicalKey::Code(KeyCode::Escape),
                &Key::Named(NamedKey::Escape),
                PRESS,
                false
            ),
            Some(Action::Quit)
        );
    }
}
