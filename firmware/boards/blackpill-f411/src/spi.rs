//! SPI1 as the emulated chip's SPI target (mode 3, MSB first, hardware NSS), served from a shadow
//! of the register file by [`margemu_firmware::spi_shadow`] (see its docs for the design, and
//! docs/boards/blackpill-f411.md for the timing budget).
//!
//! | pin | function (AF5) |
//! |-----|----------------|
//! | PA4 | SPI1_NSS (also EXTI4: the transaction handler) |
//! | PA5 | SPI1_SCK |
//! | PA6 | SPI1_MISO |
//! | PA7 | SPI1_MOSI |
//!
//! While NSS is high, DMA2 stream 3 (channel 3, SPI1_TX) is armed over the MISO stream of the
//! armed [`Shadow`] and DMA2 stream 0 (channel 3, SPI1_RX) over an [`RX`] buffer (RM0383, DMA2
//! request mapping). NSS falling raises EXTI4 at the highest priority; its handler runs
//! [`serve`] until NSS rises, then (in `Port::end`) resets SPI1 (the only way to empty its TX
//! buffer), re-arms both streams over the front shadow and the other RX buffer, and queues the
//! [`Capture`] for the main loop.
//!
//! **Sharing.** Two shadows: the main loop rewrites only the back one, and only once the handler
//! has re-armed away from it ([`SpiTarget::back`]); [`SpiTarget::publish`] makes it the front and
//! pends EXTI4 so the handler re-arms at once (when NSS is low, at the end of the transaction).
//! The handler never touches the link handler or the chip, so it needs no lock.

use core::cell::UnsafeCell;
use core::ptr::read_volatile;
use core::sync::atomic::{AtomicU32, AtomicUsize, Ordering};

use cortex_m::peripheral::NVIC;
use heapless::spsc::{Consumer, Producer, Queue};
use margemu_firmware::spi_shadow::{serve, Capture, Shadow, SpiPort, STREAM_LEN};
use stm32f4xx_hal::pac::{self, interrupt, Interrupt, DMA2, SPI1};
use stm32f4xx_hal::rcc::{Enable, Rcc, Reset};

/// DMA2 stream carrying MISO bytes from the shadow to SPI1_DR.
const TX_STREAM: usize = 3;
/// DMA2 stream carrying MOSI bytes from SPI1_DR to [`RX`].
const RX_STREAM: usize = 0;

/// DMA_SxCR (RM0383, DMA chapter): CHSEL = 3 (SPI1), PL = very high, MINC, 8-bit sizes.
const DMA_CR_COMMON: u32 = (3 << 25) | (3 << 16) | (1 << 10);
const DMA_CR_MEM_TO_PERIPH: u32 = 1 << 6;
const DMA_CR_EN: u32 = 1 << 0;
/// LIFCR: every flag of streams 0 (bits 0, 2..5) and 3 (bits 22, 24..27).
const DMA_CLEAR_FLAGS: u32 = 0x0F40_003D;

/// SPI_CR1: CPHA = 1, CPOL = 1 (mode 3), target (MSTR = 0), 8-bit, MSB first, SSM = 0
/// (NSS from the pin).
const SPI_CR1_MODE3: u16 = 0b11;
const SPI_CR1_SPE: u16 = 1 << 6;
const SPI_CR2_RXDMAEN: u16 = 1 << 0;
const SPI_CR2_TXDMAEN: u16 = 1 << 1;

/// NSS is PA4.
const NSS_PIN: u32 = 4;

/// Captures waiting for the main loop (a heapless queue of `N` holds `N - 1`).
const QUEUE_LEN: usize = 5;

/// Interrupt priority of EXTI4: the highest (BASEPRI never masks 0).
pub const PRIORITY: u8 = 0x00;

struct ShadowCell(UnsafeCell<Shadow>);
// SAFETY: the module docs' protocol: the handler uses `SHADOWS[ARMED]`, the main loop only the
// other one while it is neither armed nor front.
unsafe impl Sync for ShadowCell {}

struct RxBuffer(UnsafeCell<[u8; STREAM_LEN]>);
// SAFETY: written by DMA, read (volatile) by the handler only.
unsafe impl Sync for RxBuffer {}

struct HandlerCell(UnsafeCell<Option<Handler>>);
// SAFETY: written once by `init` before EXTI4 is unmasked; only the handler uses it afterwards.
unsafe impl Sync for HandlerCell {}

static SHADOWS: [ShadowCell; 2] = [
    ShadowCell(UnsafeCell::new(Shadow::new())),
    ShadowCell(UnsafeCell::new(Shadow::new())),
];
/// The shadow the main loop published last.
static FRONT: AtomicUsize = AtomicUsize::new(0);
/// The shadow the TX stream is armed over.
static ARMED: AtomicUsize = AtomicUsize::new(0);
/// Captures lost because the queue was full.
static DROPPED: AtomicU32 = AtomicU32::new(0);
/// MOSI bytes, one buffer for the transaction in progress (DMA target) and one for the last
/// one, still being recorded while the next is already armed.
static RX: [RxBuffer; 2] = [
    RxBuffer(UnsafeCell::new([0; STREAM_LEN])),
    RxBuffer(UnsafeCell::new([0; STREAM_LEN])),
];
/// The RX buffer armed.
static RX_ARMED: AtomicUsize = AtomicUsize::new(0);
static HANDLER: HandlerCell = HandlerCell(UnsafeCell::new(None));

struct Handler {
    producer: Producer<'static, Capture>,
    capture: Capture,
}

/// The main loop's side of the SPI target.
pub struct SpiTarget {
    consumer: Consumer<'static, Capture>,
}

impl SpiTarget {
    /// Configures SPI1, DMA2 and EXTI4 (PA4 falling) and arms the first transaction over the
    /// (all-zero) front shadow. The pins must already be in AF5 (SCK, MISO, MOSI, NSS).
    pub fn init(_spi: SPI1, _dma: DMA2, rcc: &mut Rcc) -> Self {
        SPI1::enable(rcc);
        DMA2::enable(rcc);
        pac::SYSCFG::enable(rcc);
        let queue: &'static mut Queue<Capture, QUEUE_LEN> =
            cortex_m::singleton!(: Queue<Capture, QUEUE_LEN> = Queue::new()).expect("init once");
        let (producer, consumer) = queue.split();
        // SAFETY: EXTI4 is still masked; nothing else uses HANDLER.
        unsafe {
            *HANDLER.0.get() = Some(Handler {
                producer,
                capture: Capture::new(),
            })
        };
        arm(FRONT.load(Ordering::Relaxed));
        // SAFETY: single-threaded set-up; EXTI4 is not yet unmasked.
        let (syscfg, exti) = unsafe { (&*pac::SYSCFG::ptr(), &*pac::EXTI::ptr()) };
        syscfg.exticr2().modify(|_, w| unsafe { w.exti4().bits(0) }); // port A
        exti.ftsr()
            .modify(|r, w| unsafe { w.bits(r.bits() | 1 << NSS_PIN) });
        exti.imr()
            .modify(|r, w| unsafe { w.bits(r.bits() | 1 << NSS_PIN) });
        exti.pr().write(|w| unsafe { w.bits(1 << NSS_PIN) });
        // SAFETY: the handler's state is in place; priorities are set before unmasking.
        unsafe {
            let mut nvic = cortex_m::Peripherals::steal().NVIC;
            nvic.set_priority(Interrupt::EXTI4, PRIORITY);
            NVIC::unmask(Interrupt::EXTI4);
        }
        Self { consumer }
    }

    /// The oldest transaction not yet replayed.
    pub fn take(&mut self) -> Option<Capture> {
        self.consumer.dequeue()
    }

    /// The shadow the main loop may rewrite now: the back one, unless the handler has not yet
    /// re-armed away from it (then `None`; try again next iteration).
    pub fn back(&mut self) -> Option<&mut Shadow> {
        let back = 1 - FRONT.load(Ordering::Relaxed);
        if ARMED.load(Ordering::Acquire) == back {
            return None;
        }
        // SAFETY: `back` is neither front nor armed, so the handler does not touch it, and
        // `&mut self` makes this the only reference on the main loop's side.
        Some(unsafe { &mut *SHADOWS[back].0.get() })
    }

    /// Makes the back shadow the front one; the handler re-arms over it at once.
    pub fn publish(&mut self) {
        let back = 1 - FRONT.load(Ordering::Relaxed);
        FRONT.store(back, Ordering::Release);
        NVIC::pend(Interrupt::EXTI4);
    }

    /// Captures the handler dropped because the queue was full.
    pub fn dropped(&self) -> u32 {
        DROPPED.load(Ordering::Relaxed)
    }
}

#[interrupt]
fn EXTI4() {
    // SAFETY: register blocks of peripherals this module owns since `init`.
    let exti = unsafe { &*pac::EXTI::ptr() };
    exti.pr().write(|w| unsafe { w.bits(1 << NSS_PIN) });
    // SAFETY: see `HandlerCell`.
    let Some(handler) = (unsafe { &mut *HANDLER.0.get() }).as_mut() else {
        return;
    };
    let armed = ARMED.load(Ordering::Relaxed);
    let mut port = Port::new();
    if port.selected() || port.received() > 0 {
        // SAFETY: `SHADOWS[armed]` belongs to the handler (module docs), and the main loop
        // cannot run while this highest-priority handler does.
        let shadow = unsafe { &mut *SHADOWS[armed].0.get() };
        serve(&mut port, shadow, &mut handler.capture); // re-arms in `Port::end`
        if handler.producer.enqueue(handler.capture.clone()).is_err() {
            DROPPED.fetch_add(1, Ordering::Relaxed);
        }
    } else {
        let front = FRONT.load(Ordering::Acquire);
        if front != armed {
            arm(front);
        }
    }
}

/// Resets SPI1 and arms both DMA streams for the next transaction: MISO from `SHADOWS[front]`,
/// MOSI into the RX buffer not armed last.
fn arm(front: usize) {
    // SAFETY: SPI1 and DMA2 streams 0 and 3 belong to this module since `init`.
    let (spi, dma) = unsafe { (&*SPI1::ptr(), &*DMA2::ptr()) };
    let (tx, rx) = (dma.st(TX_STREAM), dma.st(RX_STREAM));
    tx.cr().write(|w| unsafe { w.bits(0) });
    rx.cr().write(|w| unsafe { w.bits(0) });
    while tx.cr().read().en().bit_is_set() || rx.cr().read().en().bit_is_set() {}
    // SAFETY: resetting SPI1 (a bit-banded RCC write) only touches SPI1, which we own.
    unsafe { SPI1::reset_unchecked() };
    dma.lifcr().write(|w| unsafe { w.bits(DMA_CLEAR_FLAGS) });
    spi.cr1().write(|w| unsafe { w.bits(SPI_CR1_MODE3) });
    spi.cr2().write(|w| unsafe { w.bits(SPI_CR2_RXDMAEN) });
    let dr = spi.dr().as_ptr() as u32;
    // SAFETY: `front` is the front shadow; the main loop no longer writes it.
    let stream = unsafe { (*SHADOWS[front].0.get()).stream().as_ptr() } as u32;
    let rx_buffer = 1 - RX_ARMED.load(Ordering::Relaxed);
    RX_ARMED.store(rx_buffer, Ordering::Relaxed);
    let len = STREAM_LEN as u16;
    rx.par().write(|w| unsafe { w.pa().bits(dr) });
    rx.m0ar()
        .write(|w| unsafe { w.m0a().bits(RX[rx_buffer].0.get() as u32) });
    rx.ndtr().write(|w| unsafe { w.ndt().bits(len) });
    rx.cr()
        .write(|w| unsafe { w.bits(DMA_CR_COMMON | DMA_CR_EN) });
    tx.par().write(|w| unsafe { w.pa().bits(dr) });
    tx.m0ar().write(|w| unsafe { w.m0a().bits(stream) });
    tx.ndtr().write(|w| unsafe { w.ndt().bits(len) });
    tx.fcr().write(|w| unsafe { w.bits(0) }); // direct mode: one byte per request
    tx.cr()
        .write(|w| unsafe { w.bits(DMA_CR_COMMON | DMA_CR_MEM_TO_PERIPH | DMA_CR_EN) });
    // RM0383, SPI communication using DMA: RXDMAEN, streams, TXDMAEN, then SPE.
    spi.cr2()
        .write(|w| unsafe { w.bits(SPI_CR2_RXDMAEN | SPI_CR2_TXDMAEN) });
    spi.cr1()
        .write(|w| unsafe { w.bits(SPI_CR1_MODE3 | SPI_CR1_SPE) });
    ARMED.store(front, Ordering::Release);
}

/// SPI1 with its two DMA streams, as [`serve`] sees it.
struct Port {
    spi: &'static pac::spi1::RegisterBlock,
    dma: &'static pac::dma1::RegisterBlock,
    gpioa: &'static pac::gpioa::RegisterBlock,
    /// The RX buffer of this transaction.
    rx: usize,
    /// MOSI bytes stored, once `end` has re-armed the streams.
    ended: Option<usize>,
}

impl Port {
    fn new() -> Self {
        // SAFETY: peripherals this module owns since `init`; GPIOA is only read (IDR).
        unsafe {
            Self {
                spi: &*SPI1::ptr(),
                dma: &*DMA2::ptr(),
                gpioa: &*pac::GPIOA::ptr(),
                rx: RX_ARMED.load(Ordering::Relaxed),
                ended: None,
            }
        }
    }
}

impl SpiPort for Port {
    #[inline(always)]
    fn selected(&mut self) -> bool {
        self.gpioa.idr().read().bits() & (1 << NSS_PIN) == 0
    }

    #[inline(always)]
    fn received(&mut self) -> usize {
        match self.ended {
            Some(n) => n,
            None => STREAM_LEN - usize::from(self.dma.st(RX_STREAM).ndtr().read().ndt().bits()),
        }
    }

    #[inline(always)]
    fn mosi(&mut self, i: usize) -> u8 {
        if i < STREAM_LEN {
            // SAFETY: in bounds; the DMA wrote byte `i` before NDTR counted it.
            unsafe { read_volatile(RX[self.rx].0.get().cast::<u8>().add(i)) }
        } else {
            0
        }
    }

    #[inline(always)]
    fn stop_stream(&mut self) -> bool {
        let tx = self.dma.st(TX_STREAM);
        tx.cr()
            .write(|w| unsafe { w.bits(DMA_CR_COMMON | DMA_CR_MEM_TO_PERIPH) });
        while tx.cr().read().en().bit_is_set() {}
        self.spi.sr().read().txe().bit_is_clear()
    }

    #[inline(always)]
    fn stream_taken(&mut self) -> usize {
        STREAM_LEN - usize::from(self.dma.st(TX_STREAM).ndtr().read().ndt().bits())
    }

    #[inline(always)]
    fn tx_empty(&mut self) -> bool {
        self.spi.sr().read().txe().bit_is_set()
    }

    #[inline(always)]
    fn write_tx(&mut self, byte: u8) {
        self.spi.dr8().write(|w| unsafe { w.dr().bits(byte) });
    }

    fn end(&mut self) {
        // A byte whose RXNE the RX stream has not served yet is moved first (a few cycles).
        while self.spi.sr().read().rxne().bit_is_set()
            && self.dma.st(RX_STREAM).cr().read().en().bit_is_set()
        {}
        self.dma.st(TX_STREAM).cr().write(|w| unsafe { w.bits(0) });
        self.dma.st(RX_STREAM).cr().write(|w| unsafe { w.bits(0) });
        while self.dma.st(RX_STREAM).cr().read().en().bit_is_set() {}
        self.ended = Some(self.received());
        arm(FRONT.load(Ordering::Acquire)); // into the other RX buffer
    }
}
