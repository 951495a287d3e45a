//! One declaration of an enum and its names: [`named_enum!`] gives the enum `ALL`, `NAMES`, `name()`,
//! `Display` and `FromStr`, whose error, [`UnknownName`], lists the valid names.

/// A name that is none of an enum's names.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown {kind} `{given}`; valid: {}", .valid.join(", "))]
pub struct UnknownName {
    /// What the enum names ("integrator", "encoding", …).
    pub kind: &'static str,
    /// What was given.
    pub given: String,
    /// The valid names, in declaration order.
    pub valid: &'static [&'static str],
}

/// What [`named_enum!`] gives every enum it declares, for code generic over such enums (a command-line
/// parser listing the possible values, say).
pub trait Named: Copy + Send + Sync + 'static {
    /// Every variant's name, in declaration order.
    const NAMES: &'static [&'static str];
    /// The variant's name.
    fn name(self) -> &'static str;
}

/// Declares a fieldless enum whose variants each have a name:
///
/// ```
/// coin_log_names::named_enum! {
///     /// How chunks are compressed.
///     #[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
///     pub enum Compression: "compression" {
///         /// zstd.
///         #[default]
///         Zstd = "zstd",
///         /// Stored as they are.
///         None = "none",
///     }
/// }
/// assert_eq!(Compression::ALL, [Compression::Zstd, Compression::None]);
/// assert_eq!(Compression::NAMES, ["zstd", "none"]);
/// assert_eq!("none".parse::<Compression>(), Ok(Compression::None));
/// assert_eq!(Compression::Zstd.to_string(), "zstd");
/// for c in Compression::ALL {
///     assert_eq!(c.name().parse::<Compression>(), Ok(*c));
///     assert_eq!(c.to_string(), c.name());
/// }
/// assert_eq!(
///     "lz5".parse::<Compression>().unwrap_err().to_string(),
///     "unknown compression `lz5`; valid: zstd, none"
/// );
/// ```
///
/// It also implements [`Named`]. The enum must derive `Clone` and `Copy`. The string after the colon
/// names the enum in the error.
#[macro_export]
macro_rules! named_enum {
    (
        $(#[$meta:meta])*
        $vis:vis enum $name:ident : $kind:literal {
            $( $(#[$variant_meta:meta])* $variant:ident = $text:literal ),+ $(,)?
        }
    ) => {
        $(#[$meta])*
        $vis enum $name {
            $( $(#[$variant_meta])* $variant ),+
        }

        impl $name {
            /// Every variant, in declaration order.
            pub const ALL: &'static [Self] = &[$(Self::$variant),+];
            /// Every variant's name, in the order of `ALL`.
            pub const NAMES: &'static [&'static str] = &[$($text),+];

            /// The name in files and on the command line.
            #[must_use]
            pub const fn name(self) -> &'static str {
                match self {
                    $(Self::$variant => $text),+
                }
            }
        }

        impl $crate::Named for $name {
            const NAMES: &'static [&'static str] = Self::NAMES;
            fn name(self) -> &'static str {
                Self::name(self)
            }
        }

        impl ::core::fmt::Display for $name {
            fn fmt(&self, f: &mut ::core::fmt::Formatter<'_>) -> ::core::fmt::Result {
                f.write_str(self.name())
            }
        }

        impl ::core::str::FromStr for $name {
            type Err = $crate::UnknownName;
            fn from_str(s: &str) -> ::core::result::Result<Self, Self::Err> {
                Self::ALL
                    .iter()
                    .copied()
                    .find(|v| v.name() == s)
                    .ok_or_else(|| $crate::UnknownName {
                        kind: $kind,
                        given: s.to_string(),
                        valid: Self::NAMES,
                    })
            }
        }
    };
}
