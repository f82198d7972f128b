//! The shells: the command line ([`cli`], [`commands`]) and the terminal designer
//! ([`design`]), and what they share ([`common`]).

pub mod cli;
pub mod commands;
pub mod common;
pub mod design;
