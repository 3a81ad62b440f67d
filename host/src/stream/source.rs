//! What a session writes to the port: the items of its source mode, batch by batch.
//!
//! - source (a), register images: one item per output sample, the predicted image, in
//!   [`ImageBatch`]es (up to 68 MPU-9250 or 47 ICM-42688-P images per frame);
//! - source (b), the device runs the model: one item per kinematics sample, at the kinematics
//!   rate, in [`KinematicsBatch`]es (up to 28 per frame).
//!
//! Item `j` is due at its own instant (the output rate's or the kinematics rate's), and the
//! device's credit window counts items.

use super::session::{Session, SourceMode};
use margemu_model::sensor;
use margemu_protocol::link::{
    max_images_per_batch, Configure, Encoder, Image, ImageBatch, KinematicsBatch, Message,
    ModelParams, Modes, Rate, Source, MAX_KINEMATICS_PER_BATCH, TRUTH_LEN,
};
use std::io;

/// The items a session streams.
#[derive(Clone, Debug)]
pub(super) enum Items {
    /// Source (a): `Session::samples[j].image`.
    Images,
    /// Source (b): kinematics for the device's model.
    Kinematics {
        /// What Configure carries (boxed: it holds every model term).
        params: Box<ModelParams>,
        /// Kinematics sample `j` is due at `params.truth_rate.sample_time_ns(j)`.
        samples: Vec<sensor::Truth>,
    },
}

impl Session {
    /// The source mode, with the kinematics rate resolved.
    pub fn source(&self) -> SourceMode {
        match &self.items {
            Items::Images => SourceMode::Images,
            Items::Kinematics { params, .. } => SourceMode::Model {
                kinematics_hz: Some(params.truth_rate.as_hz_f64()),
            },
        }
    }

    /// Whether the device stops at once on Stop (source model) rather than serving what it
    /// holds first (source images).
    pub(super) fn stops_at_once(&self) -> bool {
        matches!(self.items, Items::Kinematics { .. })
    }

    /// Items to stream.
    pub(super) fn stream_len(&self) -> u64 {
        match &self.items {
            Items::Images => self.samples.len() as u64,
            Items::Kinematics { samples, .. } => samples.len() as u64,
        }
    }

    /// The rate of the items.
    pub(super) fn item_rate(&self) -> Rate {
        match &self.items {
            Items::Images => self.rate,
            Items::Kinematics { params, .. } => params.truth_rate,
        }
    }

    /// Bytes of one item on the wire (before framing).
    pub(super) fn item_len(&self) -> u64 {
        match &self.items {
            Items::Images => self.chip.model.image_len() as u64,
            Items::Kinematics { .. } => TRUTH_LEN as u64,
        }
    }

    /// Most items in one frame.
    pub(super) fn max_per_frame(&self) -> usize {
        match &self.items {
            Items::Images => max_images_per_batch(self.chip.model.image_len()),
            Items::Kinematics { .. } => MAX_KINEMATICS_PER_BATCH,
        }
    }

    /// The source the device must support.
    pub(super) fn required_mode(&self) -> (Modes, &'static str) {
        match &self.items {
            Items::Images => (Modes::IMAGES, "it does not take register images"),
            Items::Kinematics { .. } => (
                Modes::MODEL,
                "it cannot run the sensor model (source mode model)",
            ),
        }
    }

    /// Configure for this session's chip, rate and source.
    pub(super) fn configure_message(&self, telemetry_period_ns: u64) -> Configure {
        let source = match &self.items {
            Items::Images => Source::Images,
            Items::Kinematics { params, .. } => Source::Model(**params),
        };
        Configure {
            telemetry_period_ns,
            source,
            ..self.chip.configure(self.rate)
        }
    }

    /// Encodes the batch of items `first .. first + n` into `wire`; returns its length.
    pub(super) fn emit_batch(
        &self,
        first: u64,
        n: u64,
        encoder: &mut Encoder,
        wire: &mut [u8],
    ) -> usize {
        let range = first as usize..(first + n) as usize;
        let encoded = match &self.items {
            Items::Images => {
                let images: Vec<Image> = self.samples[range].iter().map(|s| s.image).collect();
                encoder.encode(&Message::Images(ImageBatch::new(first, &images)), wire)
            }
            Items::Kinematics { samples, .. } => {
                let batch = KinematicsBatch::new(first, &samples[range]);
                encoder.encode(&Message::Kinematics(batch), wire)
            }
        };
        encoded.expect("a batch within the frame's limits fits")
    }

    /// Logs items `first .. first + n` in `sent.csv`, written at host time `send_ns`.
    pub(super) fn log_sent(
        &mut self,
        first: u64,
        n: u64,
        send_ns: i64,
        late_ns: Option<i64>,
        resend: bool,
    ) -> io::Result<()> {
        let rate = self.item_rate();
        let rows = first..first + n;
        let range = first as usize..(first + n) as usize;
        match &self.items {
            Items::Images => {
                let images: Vec<Image> = self.samples[range].iter().map(|s| s.image).collect();
                self.log.write(move |log| {
                    rows.zip(&images).try_for_each(|(j, image)| {
                        let t_ns = rate.sample_time_ns(j);
                        log.sent_image(j, t_ns, send_ns, late_ns, image, resend)
                    })
                })
            }
            Items::Kinematics { samples, .. } => {
                let kinematics = samples[range].to_vec();
                self.log.write(move |log| {
                    rows.zip(&kinematics).try_for_each(|(j, k)| {
                        let t_ns = rate.sample_time_ns(j);
                        log.sent_kinematics(j, t_ns, send_ns, late_ns, k, resend)
                    })
                })
            }
        }
    }
}
