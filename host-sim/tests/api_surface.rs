//! The library's public surface is the one `src/lib.rs` documents: the API modules are
//! public and linked from the crate documentation; every other top-level module is
//! private, `pub(crate)`, or public only for the binary and these tests and then hidden
//! from the documentation (`#[doc(hidden)]`).

use syn::{Item, Visibility};

/// The API modules (the crate documentation's "The library's API").
const API: &[&str] = &[
    "design",
    "errors",
    "exit_code",
    "hil",
    "model",
    "results",
    "sweep",
];

/// The violations of the rule above in the text of a `lib.rs`.
fn violations(lib_rs: &str) -> Vec<String> {
    let file = syn::parse_file(lib_rs).expect("lib.rs parses");
    let crate_doc: String = file
        .attrs
        .iter()
        .filter(|a| a.path().is_ident("doc"))
        .filter_map(|a| match &a.meta {
            syn::Meta::NameValue(nv) => match &nv.value {
                syn::Expr::Lit(syn::ExprLit {
                    lit: syn::Lit::Str(s),
                    ..
                }) => Some(s.value()),
                _ => None,
            },
            _ => None,
        })
        .collect::<Vec<_>>()
        .join("\n");
    let mut found = Vec::new();
    let mut public = Vec::new();
    for item in &file.items {
        let Item::Mod(m) = item else { continue };
        let name = m.ident.to_string();
        let hidden = m.attrs.iter().any(|a| {
            a.path().is_ident("doc") && a.parse_args::<syn::Ident>().is_ok_and(|i| i == "hidden")
        });
        let is_pub = matches!(m.vis, Visibility::Public(_));
        match (is_pub, hidden, API.contains(&name.as_str())) {
            (true, false, true) => public.push(name.clone()),
            (true, false, false) => found.push(format!(
                "`pub mod {name}` is not API: hide it or make it pub(crate)"
            )),
            (_, _, true) => found.push(format!("API module `{name}` is not public and documented")),
            _ => {}
        }
        if API.contains(&name.as_str()) && !crate_doc.contains(&format!("[`{name}`]")) {
            found.push(format!(
                "API module `{name}` is not linked from the crate documentation"
            ));
        }
    }
    for name in API {
        if !public.iter().any(|p| p == name) && !found.iter().any(|f| f.contains(name)) {
            found.push(format!("API module `{name}` is missing"));
        }
    }
    found
}

#[test]
fn only_the_documented_api_is_public_in_the_docs() {
    let lib = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/src/lib.rs"))
        .expect("src/lib.rs");
    assert_eq!(violations(&lib), Vec::<String>::new());
}

/// Negative controls: an engine made public without hiding it, an API module hidden, and
/// an API module the crate documentation does not link are each reported.
#[test]
fn the_check_reports_a_leaked_or_undocumented_module() {
    let api_mods: String = API.iter().map(|m| format!("pub mod {m} {{}}\n")).collect();
    let links: String = API.iter().map(|m| format!("//! [`{m}`]\n")).collect();
    let good = format!("{links}{api_mods}#[doc(hidden)]\npub mod engine {{}}\nmod api {{}}\n");
    assert_eq!(violations(&good), Vec::<String>::new());

    let leaked = good.replace("#[doc(hidden)]\npub mod engine", "pub mod engine");
    assert_eq!(violations(&leaked).len(), 1, "{:?}", violations(&leaked));
    assert!(violations(&leaked)[0].contains("engine"));

    let hidden_api = good.replace("pub mod sweep {}", "#[doc(hidden)]\npub mod sweep {}");
    assert!(violations(&hidden_api).iter().any(|v| v.contains("sweep")));

    let unlinked = good.replace("//! [`design`]\n", "");
    assert!(violations(&unlinked).iter().any(|v| v.contains("design")));

    let missing = good.replace("pub mod hil {}\n", "");
    assert!(violations(&missing).iter().any(|v| v.contains("hil")));
}
