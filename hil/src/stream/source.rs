//! What a session writes to the port: the items of its source mode, batch by batch.
//!
//! - source (a), register images: one item per output sample, the predicted image, in
//!   [`ImageBatch`]es (up to 68 MPU-9250 or 47 ICM-42688-P images per frame);
//! - source (b), the device runs the model: one item per kinematics sample, at the kinematics
//!   rate, in [`KinematicsBatch`]es (up to 28 per frame).
//!
//! Item `j` is due at its own instant (the output rate's or the kinematics rate's), and the
//! device's credit window counts items.
//!
//! [`Source`] owns the items of a session and their [`Prediction`], read in order just before
//! they are written ([`Source::predict_through`]): each output sample read passes its image's
//! CRC-32C to the Served check and its truth to `truth.csv`. Only a [`Window`] of the newest
//! items is kept (the device's buffer capacity and four batches, `Plan::items_kept`): what a
//! go-back can still write again.

use super::images::PredictedSample;
use super::logger::Logger;
use super::predictor::Predictions;
use super::served::ServedCheck;
use super::session::SourceMode;
use super::window::Window;
use super::{ModelSample, StreamError};
use margemu_model::sensor;
use margemu_protocol::link::{
    self, max_images_per_batch, AddDevice, AddVibration, Capabilities, Configure, Encoder, Image,
    ImageBatch, KinematicsBatch, Message, ModelParams, Modes, Rate, CRC32C,
    MAX_KINEMATICS_PER_BATCH, TRUTH_LEN,
};
use margemu_sim::run::RunError;
use margemu_sim::scene::chip::ChipSetup;
use std::iter::Peekable;

/// The items a session streams.
#[derive(Clone, Debug)]
pub(super) enum Items {
    /// Source (a): the predicted image of each output sample.
    Images,
    /// Source (b): kinematics for the device's model.
    Kinematics {
        /// What Configure carries (boxed: it holds every model term).
        params: Box<ModelParams>,
        /// Output samples per kinematics sample: kinematics sample `j` is output sample
        /// `j · hold`'s, due at `params.truth_rate.sample_time_ns(j)`.
        hold: u32,
        /// The AddVibration messages that follow Configure (the chain the device runs).
        vibration: Vec<AddVibration>,
    },
}

/// One item to write.
#[derive(Clone, Copy, Debug)]
pub(super) enum Item {
    Image(Image),
    Kinematics(sensor::Truth),
}

/// Each output sample predicted, with the item it brings (every sample's image in source
/// images, every `hold`-th sample's kinematics in source model).
type Stream = Box<dyn Iterator<Item = Result<(PredictedSample, Option<Item>), RunError>> + Send>;

/// The lazy prediction of a session and the newest items it produced.
pub(super) struct Prediction {
    stream: Peekable<Stream>,
    /// The newest items predicted.
    items: Window<Item>,
    /// Output samples predicted so far.
    outputs: u64,
}

impl Prediction {
    /// Source images.
    pub(super) fn images(samples: Predictions<PredictedSample>) -> Self {
        let stream = samples.map(|r| r.map(|s| (s, Some(Item::Image(s.image)))));
        Self::of(Box::new(stream))
    }

    /// Source model.
    pub(super) fn model(samples: Predictions<ModelSample>) -> Self {
        let stream = samples.map(|r| r.map(|m| (m.sample, m.kinematics.map(Item::Kinematics))));
        Self::of(Box::new(stream))
    }

    fn of(stream: Stream) -> Self {
        Self {
            stream: stream.peekable(),
            items: Window::new(1),
            outputs: 0,
        }
    }

    /// Keeps the newest `span` items from now on (set once the plan is known, before any is
    /// predicted).
    fn keep(&mut self, span: usize) {
        self.items = Window::new(span);
    }

    /// Waits for the first sample: an error the prediction fails with at once (a reference that
    /// cannot be built, a sensor model refused) is returned here.
    pub(super) fn check_start(&mut self) -> Result<(), StreamError> {
        match self.stream.peek() {
            Some(Err(_)) => match self.stream.next() {
                Some(Err(e)) => Err(e.into()),
                _ => unreachable!("peeked an error"),
            },
            _ => Ok(()),
        }
    }
}

/// What a session streams: its items, their lazy prediction, and what they follow from (the
/// chip Configure asks for, the scene's rate and sample count).
pub(super) struct Source {
    items: Items,
    prediction: Prediction,
    /// The chip Configure asks for (the scene's `[chip]`, device 0 of a rig).
    chip: ChipSetup,
    /// The rig's other devices, one AddDevice each after Configure.
    others: Vec<ChipSetup>,
    /// The scene's output rate.
    rate: Rate,
    /// Output samples in the scene.
    samples: u64,
}

impl Source {
    /// The `items` of a scene of `samples` output samples at `rate` for `chip` (and a rig's
    /// `others`), read from `prediction`.
    pub(super) fn new(
        items: Items,
        prediction: Prediction,
        (chip, others): (ChipSetup, Vec<ChipSetup>),
        rate: Rate,
        samples: u64,
    ) -> Self {
        Self {
            items,
            prediction,
            chip,
            others,
            rate,
            samples,
        }
    }

    /// Bytes of one sample's image: the chip's, or a rig's devices' summed.
    fn image_len(&self) -> usize {
        let others: usize = self.others.iter().map(|c| c.model.image_len()).sum();
        self.chip.model.image_len() + others
    }

    /// Output samples in the scene.
    pub(super) fn samples(&self) -> u64 {
        self.samples
    }

    /// The scene's output rate.
    pub(super) fn rate(&self) -> Rate {
        self.rate
    }

    /// The source mode, with the kinematics rate resolved.
    pub(super) fn mode(&self) -> SourceMode {
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
        self.samples.div_ceil(self.hold())
    }

    /// Output samples per item.
    pub(super) fn hold(&self) -> u64 {
        match &self.items {
            Items::Images => 1,
            Items::Kinematics { hold, .. } => u64::from(*hold),
        }
    }

    /// Keeps the newest `span` items predicted (`Plan::items_kept`).
    pub(super) fn keep_items(&mut self, span: usize) {
        self.prediction.keep(span);
    }

    /// Reads the prediction until items `.. end` and every output sample they cover are
    /// predicted: their CRCs go to `served`, their truth to `truth.csv` (through `log`).
    pub(super) fn predict_through(
        &mut self,
        end: u64,
        served: &mut ServedCheck,
        log: &mut Logger,
    ) -> Result<(), StreamError> {
        let target = end.saturating_mul(self.hold()).min(self.samples);
        let p = &mut self.prediction;
        let mut truths = Vec::new();
        let mut clips = Vec::new();
        while p.outputs < target {
            let Some(next) = p.stream.next() else {
                return Err(StreamError::PredictionEnded {
                    index: p.outputs,
                    samples: self.samples,
                });
            };
            let (sample, item) = next?;
            served.expect(p.outputs, CRC32C.checksum(&sample.image));
            truths.push(sample.truth);
            clips.push((sample.truth.t_ns, sample.clips));
            if let Some(item) = item {
                p.items.push(item);
            }
            p.outputs += 1;
        }
        if truths.is_empty() {
            return Ok(());
        }
        log.queue(move |log| {
            log.truth(&truths)?;
            log.clipping(&clips)
        })
    }

    /// The kept items `first .. first + n` (a go-back never reaches further back than the
    /// window, see `Plan::items_kept`).
    fn items(&self, first: u64, n: u64) -> impl Iterator<Item = Item> + '_ {
        (first..first + n).map(|j| {
            *self
                .prediction
                .items
                .get(j)
                .expect("written items stay in the window")
        })
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
            Items::Images => self.image_len() as u64,
            Items::Kinematics { .. } => TRUTH_LEN as u64,
        }
    }

    /// Most items in one frame.
    pub(super) fn max_per_frame(&self) -> usize {
        match &self.items {
            Items::Images => max_images_per_batch(self.image_len()),
            Items::Kinematics { .. } => MAX_KINEMATICS_PER_BATCH,
        }
    }

    /// The source the device must support.
    fn required_mode(&self) -> (Modes, &'static str) {
        match &self.items {
            Items::Images => (Modes::IMAGES, "it does not take register images"),
            Items::Kinematics { .. } => (
                Modes::MODEL,
                "it cannot run the sensor model (source mode model)",
            ),
        }
    }

    /// Why a device with capabilities `caps` cannot serve this session (`None`: it can): it
    /// must emulate the chip, support the source mode, and have batch and buffer space.
    pub(super) fn refusal(&self, caps: &Capabilities) -> Option<String> {
        let (mode, no_mode) = self.required_mode();
        let models = std::iter::once(&self.chip).chain(&self.others);
        if let Some(c) = models.into_iter().find(|c| !caps.chips.has(c.model)) {
            Some(format!("it does not emulate the {}", c.model.part_name()))
        } else if !caps.modes.contains(mode) {
            Some(no_mode.to_owned())
        } else if caps.max_batch == 0 || caps.buffer_capacity == 0 {
            Some("it announces no batch or buffer space".to_owned())
        } else {
            None
        }
    }

    /// Configure for this session's chip, rate and source, and a Telemetry period.
    pub(super) fn configure_message(&self, telemetry_period_ns: u64) -> Configure {
        let source = match &self.items {
            Items::Images => link::Source::Images,
            Items::Kinematics { params, .. } => link::Source::Model(**params),
        };
        Configure {
            telemetry_period_ns,
            source,
            ..self.chip.configure(self.rate)
        }
    }

    /// One AddDevice per other device of a rig, in device order, to follow Configure.
    pub(super) fn add_device_messages(&self) -> Vec<AddDevice> {
        self.others
            .iter()
            .map(|c| c.add_device(self.rate))
            .collect()
    }

    /// The AddVibration messages of source model, in order, to follow Configure (none in
    /// source images).
    pub(super) fn add_vibration_messages(&self) -> &[AddVibration] {
        match &self.items {
            Items::Images => &[],
            Items::Kinematics { vibration, .. } => vibration,
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
        let encoded = match &self.items {
            Items::Images => {
                let images: Vec<Image> = self.items(first, n).filter_map(image_of).collect();
                encoder.encode(&Message::Images(ImageBatch::new(first, &images)), wire)
            }
            Items::Kinematics { .. } => {
                let samples: Vec<_> = self.items(first, n).filter_map(kinematics_of).collect();
                let batch = KinematicsBatch::new(first, &samples);
                encoder.encode(&Message::Kinematics(batch), wire)
            }
        };
        encoded.expect("a batch within the frame's limits fits")
    }

    /// Logs items `first .. first + n` in `sent.csv` (through `log`), written at host time
    /// `send_ns`.
    pub(super) fn log_sent(
        &self,
        log: &mut Logger,
        first: u64,
        n: u64,
        send_ns: i64,
        late_ns: Option<i64>,
        resend: bool,
    ) -> Result<(), StreamError> {
        let rate = self.item_rate();
        let rows = first..first + n;
        match &self.items {
            Items::Images => {
                let images: Vec<Image> = self.items(first, n).filter_map(image_of).collect();
                log.queue(move |log| {
                    rows.zip(&images).try_for_each(|(j, image)| {
                        let t_ns = rate.sample_time_ns(j);
                        log.sent_image(j, t_ns, send_ns, late_ns, image, resend)
                    })
                })
            }
            Items::Kinematics { .. } => {
                let kinematics: Vec<_> = self.items(first, n).filter_map(kinematics_of).collect();
                log.queue(move |log| {
                    rows.zip(&kinematics).try_for_each(|(j, k)| {
                        let t_ns = rate.sample_time_ns(j);
                        log.sent_kinematics(j, t_ns, send_ns, late_ns, k, resend)
                    })
                })
            }
        }
    }
}

fn image_of(item: Item) -> Option<Image> {
    match item {
        Item::Image(image) => Some(image),
        Item::Kinematics(_) => None,
    }
}

fn kinematics_of(item: Item) -> Option<sensor::Truth> {
    match item {
        Item::Kinematics(k) => Some(k),
        Item::Image(_) => None,
    }
}
