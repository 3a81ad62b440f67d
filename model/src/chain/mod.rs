//! A chip's sampling chain: the front end sampling at the internal rate (vibration added, range
//! clipped and counted), the digital filters, and the decimation to the output rate.

pub mod filter;
