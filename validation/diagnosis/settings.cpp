// validation/diagnosis/settings.cpp -- DiagnoseSettings::IsValid: the ranges of Describe.
#include "validation/diagnosis/settings.hpp"

namespace vrelab::validation {

bool DiagnoseSettings::IsValid(std::string* why) const { return core::validate(*this, why); }

}  // namespace vrelab::validation
