//! Chainable `with_*` setters for the settings structs, which are `#[non_exhaustive]` so that
//! new settings do not break callers: build from `Default` and replace what differs.

/// `with_setters!(Type { with_field: field: FieldType, ... })` adds
/// `pub fn with_field(self, value: FieldType) -> Self` for each listed field.
macro_rules! with_setters {
    ($ty:ty { $($setter:ident: $field:ident: $fty:ty),* $(,)? }) => {
        impl $ty {
            $(
                #[doc = concat!("These settings with `", stringify!($field), "` replaced.")]
                #[must_use]
                pub fn $setter(mut self, value: $fty) -> Self {
                    self.$field = value;
                    self
                }
            )*
        }
    };
}

pub(crate) use with_setters;
