//! The page and its assets, embedded in the binary: the page (`index.html`, `app.js`,
//! `app.css`) and the plotting library uPlot (MIT licence, `uPlot.LICENSE`).

/// The page.
pub const INDEX_HTML: &str = include_str!("assets/index.html");

/// An embedded asset by its file name: its content type and bytes.
pub fn asset(name: &str) -> Option<(&'static str, &'static str)> {
    Some(match name {
        "app.js" => ("text/javascript; charset=utf-8", include_str!("assets/app.js")),
        "app.css" => ("text/css; charset=utf-8", include_str!("assets/app.css")),
        "uPlot.iife.min.js" => (
            "text/javascript; charset=utf-8",
            include_str!("assets/uPlot.iife.min.js"),
        ),
        "uPlot.min.css" => ("text/css; charset=utf-8", include_str!("assets/uPlot.min.css")),
        "uPlot.LICENSE" => ("text/plain; charset=utf-8", include_str!("assets/uPlot.LICENSE")),
        _ => return None,
    })
}
