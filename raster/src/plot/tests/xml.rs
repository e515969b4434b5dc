//! Tests of [`xml`](crate::plot::xml): escaping, and the well-formedness check on good and
//! broken documents.

use crate::plot::xml::{check_well_formed, escape};

#[test]
fn escaped_text_is_well_formed_and_reads_back() {
    let nasty = "a<b & c>\"d\" 'e' \u{7}";
    let doc = format!("<svg a=\"{}\">{}</svg>", escape(nasty), escape(nasty));
    assert_eq!(check_well_formed(&doc), Ok("svg".to_string()));
    assert_eq!(
        escape(nasty),
        "a&lt;b &amp; c&gt;&quot;d&quot; &apos;e&apos;  "
    );
}

#[test]
fn good_documents_pass() {
    for doc in [
        "<svg/>",
        "<?xml version=\"1.0\"?>\n<svg xmlns=\"x\"><g><path d=\"M0 0\"/></g>\n</svg>\n",
        "<a><!-- <not a tag> --><b x='1' y=\"2\">t &amp; &#38;</b></a>",
    ] {
        assert!(check_well_formed(doc).is_ok(), "{doc}");
    }
}

#[test]
fn broken_documents_fail_with_the_reason() {
    for (doc, reason) in [
        ("", "no root element"),
        ("<svg>", "never closed"),
        ("<svg><g></svg>", "closes <g>"),
        ("<svg></g></svg>", "closes <svg>"),
        ("</svg>", "closes nothing"),
        ("<svg/><svg/>", "second root"),
        ("text<svg/>", "outside the root"),
        ("<svg a=1/>", "not quoted"),
        ("<svg a=\"1/>", "not closed"),
        ("<svg a=\"1\" a=\"2\"/>", "twice"),
        ("<svg a=\"1\"b=\"2\"/>", "no space"),
        ("<svg a/>", "without a value"),
        ("<svg>&nbsp;</svg>", "unknown entity"),
        ("<svg>a & b</svg>", "without ';'"),
        ("<svg a=\"<\"/>", "raw '<'"),
        ("<1svg/>", "bad tag name"),
        ("<svg", "unclosed tag"),
        ("<svg><!-- </svg>", "unclosed comment"),
        ("<?xml version=\"1.0\"", "declaration"),
    ] {
        let err = check_well_formed(doc).unwrap_err();
        assert!(err.contains(reason), "{doc}: {err}");
    }
}
