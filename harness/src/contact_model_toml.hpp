#pragma once
// The reader of a scene's [contact] table, apart from contact_model.hpp so that only the scene reader
// sees toml11.
#include <string>

#include <toml.hpp>

#include "demmat/contact_model.hpp"

namespace demmat {

// `table` is the value of the scene's "contact" key; `label` names the file in messages. Every error is
// one line naming the key: an unknown model or key, a missing parameter, a value out of range.
ContactModel parse_contact_model(const toml::value& table, const std::string& label);

} // namespace demmat
