#![doc = include_str!("../README.md")]
#![no_std]
#![warn(missing_docs)]

pub mod chain;
pub mod error;
pub mod fault;
pub mod noise;
pub mod perturbation;
pub mod rng;
pub mod sensor;
pub mod time;
pub mod vec3;
pub mod vibration;

pub use error::Error;
