// SPDX-License-Identifier: Apache-2.0
#pragma once
// The statement audit: every sentence of every region's interpretation checked against its premises, recomputed
// from analysis.json and the region's pixels by code that shares nothing with the code that wrote the sentence
// (analyzer/interpretation.cpp). docs/analyze.md ("Statements and their premises") states each premise.
//
// What it checks, for each region:
//  - every claim a statement (or the process) makes holds: its premise, recomputed here, is true;
//  - each kind of statement carries the claims its words make (a body colour claims its line reaches black …), so
//    that no sentence can skip its premise;
//  - sentences that must be there are: a body colour where the line reaches black, every channel with pixels at a
//    limit named, γ quoted where it was measured;
//  - no quoted triple of numbers — a colour or a direction — has a negative component;
//  - each statement's text is in the paragraph.
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace ct::test {

// The stored values of a region's finite pixels, [i][channel], as the analysis read them (its layer, before any
// curve was undone).
using RegionPixels = std::function<std::vector<float>(std::size_t region)>;

// One line per false or missing sentence: "region name: what is wrong". Empty when every sentence is true.
std::vector<std::string> audit_statements(const nlohmann::json& analysis, const RegionPixels& pixels);

}  // namespace ct::test
