//! The host link on USB CDC-ACM (full speed, OTG FS on PA11/PA12, the USB-C connector), polled
//! from the main loop: received bytes for `Device::feed`, and the frames of `Device::poll` sent
//! through a [`PENDING`]-byte buffer, so a frame is never cut or dropped while the IN endpoint is
//! busy.
//!
//! When a frame does not fit the buffer, [`UsbLink::send`] keeps polling the USB device until it
//! does, as long as a host has the port open (DTR set, as opening a tty does); without a host,
//! whole frames that do not fit are discarded and counted ([`UsbLink::discarded`]), so the
//! firmware never waits for a host that is not there.

use stm32f4xx_hal::otg_fs::{UsbBus, USB};
use usb_device::bus::UsbBusAllocator;
use usb_device::device::{
    StringDescriptors, UsbDevice, UsbDeviceBuilder, UsbDeviceState, UsbVidPid,
};
use usbd_serial::{SerialPort, USB_CLASS_CDC};

/// Bytes of frames waiting for the IN endpoint (more than two of the largest frame).
pub const PENDING: usize = 4096;

/// Endpoint memory of the OTG FS core, in words.
const EP_MEMORY_WORDS: usize = 320;

/// A shared test VID:PID for CDC-ACM devices (pid.codes 0x16C0:0x27DD, as in the HAL's
/// examples); Linux binds `cdc_acm` and names the port /dev/ttyACM*.
const VID_PID: UsbVidPid = UsbVidPid(0x16c0, 0x27dd);

type Bus = UsbBus<USB>;

/// The CDC link with its pending buffer.
pub struct UsbLink {
    device: UsbDevice<'static, Bus>,
    serial: SerialPort<'static, Bus>,
    pending: Ring,
    discarded: u32,
}

impl UsbLink {
    /// Brings up the USB device; `serial_number` is reported in its string descriptor.
    pub fn new(usb: USB, serial_number: &'static str) -> Self {
        let memory: &'static mut [u32; EP_MEMORY_WORDS] =
            cortex_m::singleton!(: [u32; EP_MEMORY_WORDS] = [0; EP_MEMORY_WORDS])
                .expect("created once");
        let bus: &'static UsbBusAllocator<Bus> =
            cortex_m::singleton!(: UsbBusAllocator<Bus> = UsbBus::new(usb, memory))
                .expect("created once");
        let serial = SerialPort::new(bus);
        let strings = StringDescriptors::default()
            .manufacturer("margemu")
            .product("margemu MPU-9250 emulator (Black Pill F411)")
            .serial_number(serial_number);
        let device = UsbDeviceBuilder::new(bus, VID_PID)
            .device_class(USB_CLASS_CDC)
            .strings(&[strings])
            .map(|b| b.build())
            .unwrap_or_else(|_| panic!("one string set fits"));
        Self {
            device,
            serial,
            pending: Ring::new(),
            discarded: 0,
        }
    }

    /// Services the USB device and moves pending bytes to the IN endpoint.
    pub fn poll(&mut self) {
        self.device.poll(&mut [&mut self.serial]);
        while let Some(chunk) = self.pending.front() {
            match self.serial.write(chunk) {
                Ok(n) if n > 0 => self.pending.consume(n),
                _ => break,
            }
        }
    }

    /// Received bytes, up to `buf.len()`.
    pub fn read(&mut self, buf: &mut [u8]) -> usize {
        self.serial.read(buf).unwrap_or(0)
    }

    /// Queues one frame, whole (see the module docs).
    pub fn send(&mut self, frame: &[u8]) {
        if self.pending.free() < frame.len() && !self.host_open() {
            self.discarded = self.discarded.wrapping_add(1);
            return;
        }
        let mut rest = frame;
        loop {
            rest = &rest[self.pending.push(rest)..];
            if rest.is_empty() {
                return;
            }
            self.poll();
            if !self.host_open() {
                // The host went away mid-frame: the rest is lost, and the host's decoder
                // resynchronises at the next frame delimiter.
                self.discarded = self.discarded.wrapping_add(1);
                return;
            }
        }
    }

    /// Frames discarded because no host had the port open.
    #[allow(dead_code)] // read with a debugger; no link field carries it
    pub fn discarded(&self) -> u32 {
        self.discarded
    }

    fn host_open(&self) -> bool {
        self.device.state() == UsbDeviceState::Configured && self.serial.dtr()
    }
}

/// A byte ring of [`PENDING`] bytes.
struct Ring {
    buf: [u8; PENDING],
    head: usize,
    len: usize,
}

impl Ring {
    const fn new() -> Self {
        Self {
            buf: [0; PENDING],
            head: 0,
            len: 0,
        }
    }

    fn free(&self) -> usize {
        PENDING - self.len
    }

    /// Appends as much of `bytes` as fits; returns how much.
    fn push(&mut self, bytes: &[u8]) -> usize {
        let n = bytes.len().min(self.free());
        for (i, &b) in bytes[..n].iter().enumerate() {
            self.buf[(self.head + self.len + i) % PENDING] = b;
        }
        self.len += n;
        n
    }

    /// The oldest contiguous run of pending bytes.
    fn front(&self) -> Option<&[u8]> {
        let end = (self.head + self.len).min(PENDING);
        (self.len > 0).then(|| &self.buf[self.head..end])
    }

    fn consume(&mut self, n: usize) {
        let n = n.min(self.len);
        self.head = (self.head + n) % PENDING;
        self.len -= n;
    }
}
