#pragma once
/// Text helpers shared by the study's run (study.cpp) and its outputs (study_report.cpp).
#include <string>

#include "fieldpath/field/params.h"

namespace fieldpath::app::study_detail {

std::string interpolationName(field::Interpolation interpolation);
std::string storedName(field::StoredQuantity stored);
/// A number in at most `precision` significant digits; empty when it is not finite (CSV cells).
std::string number(double value, int precision = 4);
/// "CPU model, N cores" of this machine, for the tables.
std::string machineDescription();

}  // namespace fieldpath::app::study_detail
