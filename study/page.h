// SPDX-License-Identifier: Apache-2.0
#pragma once
// The study's page, index.html (docs/study.md): self-contained (charts inlined), it says how the reference was
// made, shows the three charts, and lists every setting with its cost, its error split into Monte Carlo and
// systematic parts, and what it keeps of the reference's histogram structure, linking each setting's
// interactive analysis report.

#include <filesystem>

#include "study/study.h"

namespace ct::study {

void write_page(const std::filesystem::path& file, const StudyResult& result);

}  // namespace ct::study
