//! The shells: the command line ([`cli`], [`commands`]) and the terminal designer
//! ([`design`]), and what they share ([`common`], and the 3D view's web server, [`view`]).

pub mod cli;
pub mod commands;
pub mod common;
pub mod design;
pub mod view;
