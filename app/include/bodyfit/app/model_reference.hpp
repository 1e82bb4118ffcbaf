#pragma once
// A model's declarations as a reference a person reads: its parameters (key, type, unit, default,
// accepted values, meaning) and its outputs (kind, unit, meaning, how ensembles combine them), as
// plain text for the terminal or Markdown for the docs (`bodyfit plugins --describe NAME`).
#include <bodyfit/plugin_loader.hpp>

#include <string>

namespace bodyfit {

enum class ReferenceFormat { Text, Markdown };

/// The model's page: its name, version, ABI, description, parameters and outputs.
std::string describe_model(const PluginInfo& model, ReferenceFormat format);
/// What a declaration accepts, in words: "(0, 90)", "one of huygens, normal", "3 numbers".
std::string accepted_values(const ParameterDecl& parameter);

}  // namespace bodyfit
