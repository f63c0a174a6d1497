#pragma once
/// The study's plotting script (scripts/plot_study.py), compiled in by app/embed_text.cmake: the
/// installed program needs no checkout beside it, and python3 reads the script on its standard
/// input (no file to find, no shell).
namespace fieldpath::app::study_assets {
extern const char* const kPlotStudyPy;  ///< scripts/plot_study.py
}  // namespace fieldpath::app::study_assets
