//! taut's host tools, one command a module: `stringart` (a picture to a
//! string-art card), `template` (a 1:1 drilling template), `vectorize` (a
//! picture to plotter G-code), `text` (Hershey text to G-code), `preview`
//! (G-code or a simulator trace to a picture), `send` (a G-code file
//! streamed to the machine, Grbl's way). They share the firmware's
//! logic crate (`taut_logic`): its nail geometry, card parsers, G-code
//! parser and interpreter, kinematics and machine-time estimate, so what
//! the tools predict is what the machine does. `studio` (the [`app`]) is
//! the web app over all of them and the machine's serial port.

pub mod app;
pub mod args;
pub mod bench;
pub mod board;
pub mod cli;
pub mod gray;
pub mod hershey;
pub mod output;
pub mod plot;
pub mod preview;
pub mod progress;
pub mod raster;
pub mod render;
pub mod send;
pub mod stringart;
pub mod svg;
pub mod template;
pub mod text;
pub mod toolpath;
pub mod vectorize;
