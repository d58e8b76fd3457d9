// SPDX-License-Identifier: Apache-2.0
// Stands in for the report's 3D viewer (viewer.js with three.js) in a chromatrace built without it
// (CHROMATRACE_WEB_REPORT=OFF, no npm): lists the regions with their classes and says what is missing.
(function () {
  const data = JSON.parse(document.getElementById("analysis-data").textContent);
  document.getElementById("histogram").textContent =
    "The 3D histogram viewer was not built into this chromatrace (configured with CHROMATRACE_WEB_REPORT=OFF, " +
    "without three.js from npm). The plots in plots/ and the numbers in analysis.json hold every region.";
  for (const hint of document.querySelectorAll("main .hint")) hint.hidden = true;  // they describe the viewer
  const list = document.getElementById("region-list");
  const regions = (data.regions || []).slice().sort(function (a, b) { return (b.pixels || 0) - (a.pixels || 0); });
  for (const region of regions) {
    const item = document.createElement("div");
    item.textContent = region.name + " — " + region.class + " (" + (region.pixels || 0) + " px)";
    item.style.width = "100%";
    list.appendChild(item);
  }
  document.body.dataset.ready = "1";
})();
