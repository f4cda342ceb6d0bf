//! `#[derive(SceneFields)]`: the rows of `rubblepile check --explain` generated from a scene file's serde structs,
//! so that a key's unit, default, range and meaning are written once, on the field that parses it. The generated
//! code names `crate::io::scene_fields` and so works inside `rubblepile` only.
//!
//! On the struct, `#[scene(table = "physics.gravity")]` gives its dotted path (absent: the file's top level). On
//! every field, either `#[field(unit = …, default = …, range = …)]` (a value: `range` is a `Range` variant or
//! constructor named without its type, `Positive`, `open_closed(1.5, MAX_KAPPA)`, `Rule("…")`) or `#[field(table)]`
//! (a table, an `Option` of one or a `Vec` of them, an array of tables). `meaning = …` is the row's text; by
//! default it is the first paragraph of the field's rustdoc, verbatim, which is then written as the printed line
//! (lower case, no full stop). A field without `#[field]` is a compile error, and so is a sub-table whose struct
//! declares another path. The key is the serde name (`#[serde(rename = …)]` respected). A value row is also an
//! associated const named as the field in capitals (`GravitySpec::THETA`), which the validators read their bounds
//! from. syn's derive guide: <https://docs.rs/syn/2/syn/struct.DeriveInput.html>.
//!
//! ```
//! # mod io {
//! #     pub mod scene_fields {
//! #         pub enum Range { Positive, Rule(&'static str) }
//! #         pub struct FieldDoc {
//! #             pub key: &'static str,
//! #             pub unit: &'static str,
//! #             pub default: &'static str,
//! #             pub range: Range,
//! #             pub meaning: &'static str,
//! #         }
//! #         pub struct TableDoc { pub key: &'static str, pub array: bool, pub meaning: &'static str }
//! #         pub trait SceneFields {
//! #             const TABLE: &'static str;
//! #             fn collect(fields: &mut Vec<FieldDoc>, tables: &mut Vec<TableDoc>);
//! #         }
//! #         pub const fn same_key(a: &str, b: &str) -> bool {
//! #             let (a, b) = (a.as_bytes(), b.as_bytes());
//! #             let mut i = 0;
//! #             while i < a.len() && i < b.len() && a[i] == b[i] { i += 1; }
//! #             i == a.len() && i == b.len()
//! #         }
//! #     }
//! # }
//! use scene_derive::SceneFields;
//!
//! #[derive(serde::Deserialize, SceneFields)]
//! struct File {
//!     /// What is simulated (required).
//!     #[field(table)]
//!     scene: Scene,
//! }
//!
//! #[derive(serde::Deserialize, SceneFields)]
//! #[scene(table = "scene")]
//! struct Scene {
//!     /// end time of the run
//!     #[field(unit = "s", default = "required", range = Positive)]
//!     t_end: f64,
//!     #[field(unit = "text", default = "none", range = Rule("a name"), meaning = "what it is called")]
//!     #[serde(rename = "Name")]
//!     name: String,
//! }
//!
//! # fn main() {
//! use io::scene_fields::SceneFields as _;
//! let (mut fields, mut tables) = (Vec::new(), Vec::new());
//! File::collect(&mut fields, &mut tables);
//! let keys: Vec<_> = fields.iter().map(|f| (f.key, f.meaning)).collect();
//! assert_eq!(keys, [("scene.t_end", "end time of the run"), ("scene.Name", "what it is called")]);
//! assert_eq!(Scene::T_END.unit, "s");
//! assert_eq!((tables[0].key, tables[0].meaning), ("scene", "What is simulated (required)."));
//! # }
//! ```
//!
//! A field without a row does not compile:
//!
//! ```compile_fail
//! # mod io {
//! #     pub mod scene_fields {
//! #         pub enum Range { Positive, Rule(&'static str) }
//! #         pub struct FieldDoc {
//! #             pub key: &'static str,
//! #             pub unit: &'static str,
//! #             pub default: &'static str,
//! #             pub range: Range,
//! #             pub meaning: &'static str,
//! #         }
//! #         pub struct TableDoc { pub key: &'static str, pub array: bool, pub meaning: &'static str }
//! #         pub trait SceneFields {
//! #             const TABLE: &'static str;
//! #             fn collect(fields: &mut Vec<FieldDoc>, tables: &mut Vec<TableDoc>);
//! #         }
//! #         pub const fn same_key(a: &str, b: &str) -> bool {
//! #             let (a, b) = (a.as_bytes(), b.as_bytes());
//! #             let mut i = 0;
//! #             while i < a.len() && i < b.len() && a[i] == b[i] { i += 1; }
//! #             i == a.len() && i == b.len()
//! #         }
//! #     }
//! # }
//! #[derive(scene_derive::SceneFields)]
//! struct Scene {
//!     t_end: f64,
//! }
//! # fn main() {}
//! ```
//!
//! Nor does a sub-table whose struct declares another path than the one its parent reads it under:
//!
//! ```compile_fail
//! # mod io {
//! #     pub mod scene_fields {
//! #         pub enum Range { Positive, Rule(&'static str) }
//! #         pub struct FieldDoc {
//! #             pub key: &'static str,
//! #             pub unit: &'static str,
//! #             pub default: &'static str,
//! #             pub range: Range,
//! #             pub meaning: &'static str,
//! #         }
//! #         pub struct TableDoc { pub key: &'static str, pub array: bool, pub meaning: &'static str }
//! #         pub trait SceneFields {
//! #             const TABLE: &'static str;
//! #             fn collect(fields: &mut Vec<FieldDoc>, tables: &mut Vec<TableDoc>);
//! #         }
//! #         pub const fn same_key(a: &str, b: &str) -> bool {
//! #             let (a, b) = (a.as_bytes(), b.as_bytes());
//! #             let mut i = 0;
//! #             while i < a.len() && i < b.len() && a[i] == b[i] { i += 1; }
//! #             i == a.len() && i == b.len()
//! #         }
//! #     }
//! # }
//! #[derive(scene_derive::SceneFields)]
//! struct File {
//!     #[field(table, meaning = "what is simulated")]
//!     scene: Scene,
//! }
//! #[derive(scene_derive::SceneFields)]
//! #[scene(table = "stepping")]
//! struct Scene {}
//! # fn main() {}
//! ```

#![warn(missing_docs)]

use proc_macro::TokenStream;
use proc_macro2::TokenStream as Tokens;
use quote::{format_ident, quote};
use syn::{
    Attribute, Data, DeriveInput, Expr, Fields, GenericArgument, LitStr, PathArguments, Type, parse_macro_input,
};

/// Derives `crate::io::scene_fields::SceneFields` (see the crate header).
#[proc_macro_derive(SceneFields, attributes(scene, field))]
pub fn derive_scene_fields(input: TokenStream) -> TokenStream {
    let input = parse_macro_input!(input as DeriveInput);
    expand(&input).unwrap_or_else(syn::Error::into_compile_error).into()
}

/// What one `#[field(…)]` says.
#[derive(Default)]
struct FieldAttr {
    table: bool,
    unit: Option<Expr>,
    default: Option<Expr>,
    range: Option<Expr>,
    meaning: Option<Expr>,
}

fn expand(input: &DeriveInput) -> syn::Result<Tokens> {
    let name = &input.ident;
    let table = struct_table(&input.attrs)?;
    let Data::Struct(data) = &input.data else {
        return Err(syn::Error::new_spanned(name, "SceneFields derives for structs only"));
    };
    let Fields::Named(fields) = &data.fields else {
        return Err(syn::Error::new_spanned(name, "SceneFields needs named fields"));
    };
    let scope = quote!(crate::io::scene_fields);
    let (mut consts, mut leaves, mut tables, mut checks) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for field in &fields.named {
        let ident = field.ident.as_ref().expect("named field");
        let attr = field_attr(field)?;
        let key = join(&table, &serde_name(field)?);
        let meaning = match &attr.meaning {
            Some(m) => quote!(#m),
            None => {
                let doc = doc_summary(&field.attrs).ok_or_else(|| {
                    syn::Error::new_spanned(ident, "a scene field needs rustdoc or `meaning = …` for its row")
                })?;
                quote!(#doc)
            }
        };
        if attr.table {
            let (child, array) = table_type(&field.ty);
            tables.push(quote! {
                tables.push(#scope::TableDoc { key: #key, array: #array, meaning: #meaning });
                <#child as #scope::SceneFields>::collect(fields, tables);
            });
            let message = format!("the struct of `{key}` needs #[scene(table = \"{key}\")]");
            checks.push(quote! {
                const _: () = assert!(#scope::same_key(<#child as #scope::SceneFields>::TABLE, #key), #message);
            });
            continue;
        }
        let missing = |what: &str| syn::Error::new_spanned(ident, format!("#[field] of a value needs `{what} = …`"));
        let unit = attr.unit.ok_or_else(|| missing("unit"))?;
        let default = attr.default.ok_or_else(|| missing("default"))?;
        let range = range_tokens(attr.range.ok_or_else(|| missing("range"))?);
        let constant = format_ident!("{}", ident.to_string().to_uppercase());
        let doc = format!("The row of `{key}`.");
        consts.push(quote! {
            #[doc = #doc]
            pub const #constant: #scope::FieldDoc = #scope::FieldDoc {
                key: #key, unit: #unit, default: #default, range: #range, meaning: #meaning,
            };
        });
        leaves.push(quote!(fields.push(Self::#constant);));
    }
    Ok(quote! {
        #[allow(dead_code)]
        impl #name { #(#consts)* }
        impl #scope::SceneFields for #name {
            const TABLE: &'static str = #table;
            fn collect(fields: &mut Vec<#scope::FieldDoc>, tables: &mut Vec<#scope::TableDoc>) {
                #(#leaves)*
                #(#tables)*
            }
        }
        #(#checks)*
    })
}

/// `table` of the struct's `#[scene(table = "…")]`, or `` (the top level).
fn struct_table(attrs: &[Attribute]) -> syn::Result<String> {
    let mut table = String::new();
    for attr in attrs.iter().filter(|a| a.path().is_ident("scene")) {
        attr.parse_nested_meta(|meta| {
            if meta.path.is_ident("table") {
                table = meta.value()?.parse::<LitStr>()?.value();
                Ok(())
            } else {
                Err(meta.error("expected `table = \"…\"`"))
            }
        })?;
    }
    Ok(table)
}

fn field_attr(field: &syn::Field) -> syn::Result<FieldAttr> {
    let mut out = FieldAttr::default();
    let mut found = false;
    for attr in field.attrs.iter().filter(|a| a.path().is_ident("field")) {
        found = true;
        attr.parse_nested_meta(|meta| {
            let slot = if meta.path.is_ident("table") {
                out.table = true;
                return Ok(());
            } else if meta.path.is_ident("unit") {
                &mut out.unit
            } else if meta.path.is_ident("default") {
                &mut out.default
            } else if meta.path.is_ident("range") {
                &mut out.range
            } else if meta.path.is_ident("meaning") {
                &mut out.meaning
            } else {
                return Err(meta.error("expected table, unit, default, range or meaning"));
            };
            *slot = Some(meta.value()?.parse()?);
            Ok(())
        })?;
    }
    if !found {
        return Err(syn::Error::new_spanned(
            field,
            "every scene field needs a row: #[field(unit = …, default = …, range = …)] or #[field(table)]",
        ));
    }
    Ok(out)
}

/// The key serde reads the field under: its `rename`, else its name.
fn serde_name(field: &syn::Field) -> syn::Result<String> {
    let mut name = field.ident.as_ref().expect("named field").to_string();
    for attr in field.attrs.iter().filter(|a| a.path().is_ident("serde")) {
        attr.parse_nested_meta(|meta| {
            if meta.path.is_ident("rename") {
                name = meta.value()?.parse::<LitStr>()?.value();
            } else if meta.input.peek(syn::Token![=]) {
                meta.value()?.parse::<Expr>()?;
            } else if meta.input.peek(syn::token::Paren) {
                meta.parse_nested_meta(|inner| {
                    if inner.input.peek(syn::Token![=]) {
                        inner.value()?.parse::<Expr>()?;
                    }
                    Ok(())
                })?;
            }
            Ok(())
        })?;
    }
    Ok(name)
}

/// `table.key`, or `key` at the top level.
fn join(table: &str, key: &str) -> String {
    if table.is_empty() {
        key.to_string()
    } else {
        format!("{table}.{key}")
    }
}

/// The first paragraph of the rustdoc, its lines joined by spaces.
fn doc_summary(attrs: &[Attribute]) -> Option<String> {
    let mut lines = Vec::new();
    for attr in attrs.iter().filter(|a| a.path().is_ident("doc")) {
        let syn::Meta::NameValue(nv) = &attr.meta else { continue };
        let Expr::Lit(syn::ExprLit {
            lit: syn::Lit::Str(s), ..
        }) = &nv.value
        else {
            continue;
        };
        let line = s.value().trim().to_string();
        if line.is_empty() {
            if lines.is_empty() {
                continue;
            }
            break;
        }
        lines.push(line);
    }
    (!lines.is_empty()).then(|| lines.join(" "))
}

/// The struct a table field holds and whether it is an array of tables: `T`, `Option<T>` or `Vec<T>` (array).
fn table_type(ty: &Type) -> (&Type, bool) {
    if let Type::Path(p) = ty
        && let Some(last) = p.path.segments.last()
        && (last.ident == "Option" || last.ident == "Vec")
        && let PathArguments::AngleBracketed(args) = &last.arguments
        && let Some(GenericArgument::Type(inner)) = args.args.first()
    {
        return (inner, last.ident == "Vec");
    }
    (ty, false)
}

/// `Positive` → `Range::Positive`, `open(0.0, 1.0)` → `Range::open(0.0, 1.0)`; any other expression as written.
fn range_tokens(range: Expr) -> Tokens {
    let scope = quote!(crate::io::scene_fields::Range);
    match range {
        Expr::Path(p) if p.path.get_ident().is_some() => {
            let ident = p.path.get_ident();
            quote!(#scope::#ident)
        }
        Expr::Call(call) => match &*call.func {
            Expr::Path(p) if p.path.get_ident().is_some() => {
                let (ident, args) = (p.path.get_ident(), &call.args);
                quote!(#scope::#ident(#args))
            }
            _ => quote!(#call),
        },
        other => quote!(#other),
    }
}
