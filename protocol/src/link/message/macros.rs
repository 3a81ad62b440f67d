//! Declarative helpers for the messages' one-byte codes and bit sets.

/// A fieldless enum stored as one byte, with `from_u8` (unknown codes give `None`).
macro_rules! code_enum {
    ($(#[$m:meta])* pub enum $name:ident { $($(#[$vm:meta])* $variant:ident = $code:literal,)* }) => {
        $(#[$m])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        #[cfg_attr(feature = "defmt", derive(defmt::Format))]
        #[repr(u8)]
        pub enum $name {
            $($(#[$vm])* $variant = $code,)*
        }

        impl $name {
            /// The value of a code byte, if it is one of the documented codes.
            pub fn from_u8(code: u8) -> Option<Self> {
                match code {
                    $($code => Some(Self::$variant),)*
                    _ => None,
                }
            }

            #[allow(dead_code)]
            pub(crate) fn read(
                r: &mut $crate::link::wire::Reader<'_>,
            ) -> Result<Self, $crate::link::Error> {
                Self::from_u8(r.u8()?).ok_or($crate::link::Error::InvalidValue)
            }
        }
    };
}

/// A set of one-bit flags in a byte; unknown bits are kept (a newer peer may set them).
macro_rules! flags {
    ($(#[$m:meta])* pub struct $name:ident { $($(#[$fm:meta])* const $flag:ident = $bit:literal;)* }) => {
        $(#[$m])*
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
        #[cfg_attr(feature = "defmt", derive(defmt::Format))]
        pub struct $name(pub u8);

        impl $name {
            $($(#[$fm])* pub const $flag: Self = Self(1 << $bit);)*
            /// No flag set.
            pub const EMPTY: Self = Self(0);

            /// Whether every flag of `other` is set in `self`.
            pub fn contains(self, other: Self) -> bool {
                self.0 & other.0 == other.0
            }
        }

        impl core::ops::BitOr for $name {
            type Output = Self;
            fn bitor(self, rhs: Self) -> Self {
                Self(self.0 | rhs.0)
            }
        }
    };
}
