// SPDX-License-Identifier: Apache-2.0
#pragma once
// Channel names of spectral OpenEXR files (the layout of Fichet, Pacanowski and Wilkie, JCGT 10(3), 2021,
// with chromatrace's component layers; see docs/spectral-exr.md).
//
// Grammar, read from the right because layer names may contain dots (`light.ceiling.S0.550,000000nm`):
//   name       = [ layer "." ] quantity "." wavelength [ "." wavelength ]     (second wavelength: T only)
//   quantity   = "S0" | "S1" | "S2" | "S3" | "T"
//   wavelength = number [ prefix ] ( "m" | "Hz" )
//   number     = digits [ "," digits ] [ ("e" | "E") [ "+" | "-" ] digits ]   (comma decimal separator,
//                since "." separates layers; at least one digit before the exponent)
//   prefix     = "Y" | "Z" | "E" | "P" | "T" | "G" | "M" | "k" | "h" | "da" | "d" | "c" | "m" | "u" | "n" | "p"
// Frequencies become wavelengths through λ = c / f.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace ct {

// What a spectral channel holds: a Stokes component of emitted radiance, or reflectance/transmittance.
enum class SpectralQuantity { S0, S1, S2, S3, T };

// "S0" … "S3", "T".
std::string_view quantity_name(SpectralQuantity quantity);

struct SpectralChannelName {
  std::string layer;  // component layer, "" for the total (e.g. "light.ceiling")
  SpectralQuantity quantity = SpectralQuantity::S0;
  double wavelength_nm = 0;             // the band centre (for T.a.b: the incident wavelength a)
  std::optional<double> reradiated_nm;  // T.a.b (bi-spectral re-radiation): the re-emitted wavelength b

  bool operator==(const SpectralChannelName&) const = default;
};

// Parses "<value><unit>" (e.g. "550,000000nm", "0,55um", "545077196,5GHz") into nm. Empty if the text does
// not follow the grammar or does not give a positive, finite wavelength.
std::optional<double> parse_wavelength_nm(std::string_view text);

// Parses a whole channel name. Empty for any name outside the grammar (R, G, B, object_id, S4.550nm,
// S0.550, S0.abcnm …): readers list such channels but do not treat them as spectral.
std::optional<SpectralChannelName> parse_spectral_channel_name(std::string_view name);

// The name chromatrace writes: wavelength in nm with six decimals and a comma, as the reference library
// does (std::to_string), e.g. ("", S0, 550) -> "S0.550,000000nm", ("light.ceiling", S0, 412.5) ->
// "light.ceiling.S0.412,500000nm".
std::string format_spectral_channel_name(std::string_view layer, SpectralQuantity quantity, double wavelength_nm);

// chromatrace's component layers come in families; the members of a family sum to the total.
enum class ComponentFamily {
  PathType,    // emission, diffuse_direct, diffuse_indirect, glossy_direct, glossy_indirect,
               // transmission_direct, transmission_indirect
  LightGroup,  // light.<group>, group made of letters, digits, '_' and '-'
  Bounce,      // bounce.<k>: paths with exactly k scattering events, k a whole number
  Unknown,     // any other layer (files from other writers)
};

ComponentFamily component_family(std::string_view layer);
// "path types", "light groups", "bounces", "other layers".
std::string_view family_name(ComponentFamily family);
// The seven path-type components, in the order the layout lists them.
const std::vector<std::string>& path_type_components();
// Whether a set of path-type components covers all light: emission and the four diffuse and glossy ones,
// plus both transmission ones or neither (files of scenes without transmissive materials omit them).
bool path_types_complete(const std::vector<std::string>& components);

}  // namespace ct
