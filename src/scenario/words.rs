//! The words a scenario file uses for a chain's fixed ends, a cloth's fixed corners and its
//! plane: each word is parsed here, from one table per kind, which the validation's list of
//! accepted words also reads.

/// A table of words and the values they name.
type Words<T> = [(&'static str, T)];

/// The value `word` names in `table`, if any.
fn parse<T: Copy>(table: &Words<T>, word: &str) -> Option<T> {
    table.iter().find(|(w, _)| *w == word).map(|&(_, v)| v)
}

/// The words of `table`, in order.
fn words<T>(table: &Words<T>) -> Vec<&'static str> {
    table.iter().map(|(w, _)| *w).collect()
}

/// An end of a `[[chain]]` that `fix` may hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ChainEnd {
    /// The particle at `start`.
    First,
    /// The particle at `end`.
    Last,
}

const CHAIN_ENDS: [(&str, ChainEnd); 2] = [("first", ChainEnd::First), ("last", ChainEnd::Last)];

impl ChainEnd {
    /// The end `word` names.
    pub fn parse(word: &str) -> Option<Self> {
        parse(&CHAIN_ENDS, word)
    }
    /// Every word `fix` accepts.
    pub fn words() -> Vec<&'static str> {
        words(&CHAIN_ENDS)
    }
}

/// A corner of a `[[cloth]]` that `fix` may hold (top: the grid's last row).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Corner {
    /// First column, last row.
    TopLeft,
    /// Last column, last row.
    TopRight,
    /// First column, first row.
    BottomLeft,
    /// Last column, first row.
    BottomRight,
}

const CORNERS: [(&str, Corner); 4] = [
    ("top_left", Corner::TopLeft),
    ("top_right", Corner::TopRight),
    ("bottom_left", Corner::BottomLeft),
    ("bottom_right", Corner::BottomRight),
];

impl Corner {
    /// The corner `word` names.
    pub fn parse(word: &str) -> Option<Self> {
        parse(&CORNERS, word)
    }
    /// Every word `fix` accepts.
    pub fn words() -> Vec<&'static str> {
        words(&CORNERS)
    }
}

/// The plane a `[[cloth]]` lies in: its rows run along x, its columns along y or z.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Plane {
    /// Hanging: columns along y (the default).
    #[default]
    Xy,
    /// Horizontal: columns along z.
    Xz,
}

const PLANES: [(&str, Plane); 2] = [("xy", Plane::Xy), ("xz", Plane::Xz)];

impl Plane {
    /// The plane `word` names.
    pub fn parse(word: &str) -> Option<Self> {
        parse(&PLANES, word)
    }
    /// Every word `plane` accepts.
    pub fn words() -> Vec<&'static str> {
        words(&PLANES)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Oracle: the file format's documented words (`ChainSpec::fix`, `ClothSpec::fix`,
    /// `ClothSpec::plane`); each parses to its own value and nothing else parses.
    #[test]
    fn each_word_names_one_value() {
        assert_eq!(ChainEnd::words(), ["first", "last"]);
        assert_eq!(ChainEnd::parse("last"), Some(ChainEnd::Last));
        assert_eq!(
            Corner::words(),
            ["top_left", "top_right", "bottom_left", "bottom_right"]
        );
        assert_eq!(Corner::parse("bottom_left"), Some(Corner::BottomLeft));
        assert_eq!(Plane::parse("xz"), Some(Plane::Xz));
        assert_eq!(Plane::parse("XZ"), None);
        assert_eq!(Corner::parse("top"), None);
    }
}
