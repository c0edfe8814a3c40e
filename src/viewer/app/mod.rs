//! The winit application: one window, one surface, one renderer. Every redraw is a frame:
//! due actions, a batch of samples, the display pass, the title.

mod actions;
mod frame;
mod state;
mod surface;

use crate::input_file::FileRead;
use crate::kernel::KernelScene;
use crate::render::BatchSizer;
use crate::scene::Scene;
use crate::viewer::action::Action;
use crate::viewer::denoised::DenoisedView;
use crate::viewer::input::InputState;
use crate::viewer::watch::{BackgroundLoad, FileWatch};
use crate::viewer::{ViewOptions, FRAME_TARGET};
use anyhow::{Context, Result};
use state::*;
use std::time::Instant;
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::window::WindowId;

pub fn run(
    event_loop: EventLoop<()>,
    scene: Scene,
    kernel: KernelScene,
    reads: Vec<FileRead>,
    mut options: ViewOptions,
) -> Result<()> {
    // Progressive rendering never idles: the image refines while nothing happens.
    event_loop.set_control_flow(ControlFlow::Poll);
    let script = std::mem::take(&mut options.script);
    let display = options.display;
    let mut app = App {
        watch: {
            let mut watch = FileWatch::new(&options.scene);
            watch.adopt(reads, true);
            watch
        },
        loader: BackgroundLoad::new(&options.scene).with_model(options.model.clone()),
        sizer: BatchSizer::new(FRAME_TARGET),
        file_camera: scene.camera.clone(),
        camera: scene.camera.clone(),
        file_integrator: scene.render.integrator,
        integrator: scene.render.integrator,
        scene,
        kernel,
        options,
        script,
        camera_moved: false,
        restarted: true,
        display,
        aovs: false,
        denoised: DenoisedView::default(),
        generation: 0,
        denoise_note: None,
        integrator_note: None,
        input: InputState::default(),
        gpu: None,
        pending_size: None,
        frame: 0,
        started: Instant::now(),
        last_frame_start: None,
        scene_error: None,
        title: TitleStats::new(),
        result: Ok(()),
        finished: false,
    };
    event_loop.run_app(&mut app).context("window event loop")?;
    app.result
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gpu.is_some() || self.finished {
            return;
        }
        if let Err(e) = self.open(event_loop) {
            self.fail(e, event_loop);
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let action = match event {
            WindowEvent::CloseRequested => Some(Action::Quit),
            WindowEvent::Resized(size) => {
                self.pending_size = Some(size);
                None
            }
            WindowEvent::RedrawRequested => {
                if !self.finished {
                    if let Err(e) = self.frame(event_loop) {
                        self.fail(e, event_loop);
                    }
                }
                None
            }
            WindowEvent::Focused(false) => {
                self.input.focus_lost();
                None
            }
            WindowEvent::KeyboardInput { event, .. } => self.input.key(
                event.physical_key,
                &event.logical_key,
                event.state,
                event.repeat,
            ),
            WindowEvent::MouseInput { state, button, .. } => {
                self.input.mouse_button(button, state);
                None
            }
            WindowEvent::CursorMoved { position, .. } => {
                self.input.cursor_moved(position.x, position.y)
            }
            WindowEvent::CursorLeft { .. } => {
                self.input.cursor_left();
                None
            }
            WindowEvent::MouseWheel { delta, .. } => self.input.wheel(delta),
            _ => None,
        };
        if let Some(action) = action {
            if let Err(e) = self.apply(action, event_loop) {
                self.fail(e, event_loop);
            }
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(gpu) = &self.gpu {
            if !self.finished {
                gpu.window.request_redraw();
            }
        }
    }
}
