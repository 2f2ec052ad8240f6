//! How a quantity of `crate::units` is written to JSON: the bare number,
//! under a key of the wire struct that names its unit (`target_mm: Mm`,
//! `mean_up_arcsec: Option<Arcsec>`).

use serde::{Serialize, Serializer};

use crate::units::{Arcsec, Deg, Mm, Um, Urad};

macro_rules! bare_number {
    ($($quantity:ty),*) => {
        $(
            impl Serialize for $quantity {
                fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
                    serializer.serialize_f64(self.0)
                }
            }
        )*
    };
}

bare_number!(Mm, Um, Deg, Arcsec, Urad);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_quantity_is_its_bare_number() {
        assert_eq!(serde_json::to_string(&Deg(90.0)).unwrap(), "90.0");
        assert_eq!(serde_json::to_string(&Some(Um(2.5))).unwrap(), "2.5");
        assert_eq!(
            serde_json::to_string(&[Mm(0.1), Mm(-3.0)]).unwrap(),
            "[0.1,-3.0]"
        );
    }
}
