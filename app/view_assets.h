#pragma once
/// The page template, style and script of `fieldpath view` (app/view/), compiled in by
/// app/embed_text.cmake so that the installed program needs no data folder of its own.
namespace fieldpath::app::view_assets {
extern const char* const kPageHtml;  ///< app/view/page.html
extern const char* const kViewCss;   ///< app/view/view.css
extern const char* const kColoursJs;  ///< app/view/colours.js (before view.js)
extern const char* const kGeometryJs;  ///< app/view/geometry.js (after colours.js)
extern const char* const kViewJs;    ///< app/view/view.js (after geometry.js)
extern const char* const kPanelJs;   ///< app/view/panel.js (after view.js, in its function scope)
extern const char* const kStateJs;   ///< app/view/state.js (after panel.js, in its function scope)
}  // namespace fieldpath::app::view_assets
