#pragma once
// io/formats/settings_json.hpp -- a described settings struct (core/settings_description.hpp)
// as a JSON object: every field by its name (a described field's as a nested object).
#include <type_traits>

#include <nlohmann/json.hpp>

#include "core/settings_description.hpp"

namespace vrelab::io {

template <class S>
nlohmann::json settings_json(const S& s) {
  nlohmann::json j = nlohmann::json::object();
  core::for_each_field<S>([&](const auto& f) {
    using T = typename std::decay_t<decltype(f)>::Type;
    if constexpr (core::Described<T>) j[std::string(f.name)] = settings_json(s.*f.member);
    else j[std::string(f.name)] = s.*f.member;
  });
  return j;
}

}  // namespace vrelab::io
