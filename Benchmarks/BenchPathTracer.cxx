// Efficiency of the path tracer's variance and cost techniques, each measured
// separately on the same scenes in one run (a bench CLI, not a test).
//
//   BenchPathTracer [--size W H] [--seconds S] [--threads N] [--seed K] [--block-voxels B]
//                   SCENE.json...
//
// For each scene (its camera resized to W x H, default 80 x 60) the path tracer runs
// for about S seconds (default 10; rounds of doubling samples, so a run ends after the
// first round past S) with PathTracingSettings' defaults ("all"), with each default
// technique off in turn ("defaults - name") or alone ("only name"), with an optional
// technique added ("defaults + name"), and with none ("none"). Efficiency = 1 / (relative error^2 x
// seconds), the relative error being the image-wide one (ImageRelativeError); it does not depend on
// the run's length, and the time to a target error e at the scene's own size is
//     t(e) = err^2 seconds / e^2 x (scene pixels / bench pixels).
// The table gives that time for 1 % and, per technique, its speed-up: eff(defaults) /
// eff(defaults without it) and eff(it alone) / eff(none) (optional techniques:
// eff(defaults with it) / eff(defaults)).
#include "DensityGridFromImage.h"
#include "PathTracer.h"
#include "RenderContext.h"
#include "SceneAssets.h"
#include "SceneJson.h"
#include "vtkNimbusSceneDensitySource.h"

#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPointData.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

namespace
{
struct Technique
{
  const char* Name;
  std::function<void(nimbus::PathTracingSettings&, bool)> Set;
  bool OnByDefault = true; // in PathTracingSettings; "all" is the defaults
};

std::vector<Technique> Techniques()
{
  return {
    { "sun-peak", [](nimbus::PathTracingSettings& s, bool on) { s.SunPeakSampling = on; } },
    { "air-sun-table",
      [](nimbus::PathTracingSettings& s, bool on) { s.TabulatedAirTransmittance = on; } },
    { "dda-blocks", [](nimbus::PathTracingSettings& s, bool on) { s.BlockTraversal = on; } },
    { "adaptive-sampling", [](nimbus::PathTracingSettings& s, bool on) { s.AdaptiveSampling = on; },
      false },
    { "sun-depth-roulette",
      [](nimbus::PathTracingSettings& s, bool on) { s.SunDepthRoulette = on; } },
  };
}

nimbus::DensityGrid SceneGrid(const std::string& file)
{
  vtkNew<vtkNimbusSceneDensitySource> source;
  source->SetSceneFileName(file.c_str());
  source->Update();
  vtkImageData* image = source->GetOutput();
  return nimbus::DensityGridFromImage(image, image->GetPointData()->GetArray(0));
}

struct Run
{
  double Error = 0.0, Seconds = 0.0, Spp = 0.0;
  double Efficiency() const { return 1.0 / (this->Error * this->Error * this->Seconds); }
};
} // namespace

int main(int argc, char* argv[])
{
  int width = 80, height = 60, threads = 0, blockVoxels = 4;
  double seconds = 10.0;
  std::uint64_t seed = 1;
  std::vector<std::string> scenes;
  for (int i = 1; i < argc; ++i)
  {
    const std::string a = argv[i];
    if (a == "--size" && i + 2 < argc)
    {
      width = std::atoi(argv[++i]);
      height = std::atoi(argv[++i]);
    }
    else if (a == "--seconds" && i + 1 < argc)
    {
      seconds = std::atof(argv[++i]);
    }
    else if (a == "--block-voxels" && i + 1 < argc)
    {
      blockVoxels = std::atoi(argv[++i]);
    }
    else if (a == "--threads" && i + 1 < argc)
    {
      threads = std::atoi(argv[++i]);
    }
    else if (a == "--seed" && i + 1 < argc)
    {
      seed = std::strtoull(argv[++i], nullptr, 10);
    }
    else if (!a.empty() && a[0] != '-')
    {
      scenes.push_back(a);
    }
    else
    {
      std::fprintf(stderr,
        "usage: BenchPathTracer [--size W H] [--seconds S] [--threads N] [--seed K] "
        "[--block-voxels B] SCENE.json...\n");
      return 2;
    }
  }
  if (scenes.empty() || width < 1 || height < 1 || !(seconds > 0.0) || blockVoxels < 1)
  {
    std::fprintf(stderr, "BenchPathTracer: need scenes, a positive size and seconds\n");
    return 2;
  }
  const std::vector<Technique> techniques = Techniques();
  std::printf(
    "| scene | configuration | spp | seconds | relative error | "
    "efficiency | time to 1 %% at the scene's size (2 cores) |\n|---|---|---|---|---|---|---|\n");
  std::fflush(stdout);
  for (const std::string& file : scenes)
  {
    nimbus::SceneDescription scene = nimbus::LoadScene(file);
    nimbus::LoadSceneAssets(scene); // a version-4 scene's light maps and meshes
    const double scale = static_cast<double>(scene.Camera.Width) * scene.Camera.Height /
      (static_cast<double>(width) * height);
    scene.Camera.Width = width;
    scene.Camera.Height = height;
    const nimbus::RenderContext context(scene, SceneGrid(file));
    auto render = [&](const std::function<void(nimbus::PathTracingSettings&)>& configure)
    {
      nimbus::PathTracingSettings settings;
      settings.MinSamplesPerPixel = 16;
      settings.MaxSamplesPerPixel = 1 << 24;
      settings.TimeLimitSeconds = seconds;
      settings.Threads = threads;
      settings.Seed = seed;
      settings.MajorantBlockVoxels = blockVoxels;
      configure(settings);
      const nimbus::PathTracingResult result = nimbus::RenderPathTraced(context, settings);
      Run run;
      run.Error = result.ImageRelativeError;
      run.Seconds = result.Seconds;
      run.Spp = result.MeanSamplesPerPixel;
      return run;
    };
    auto report = [&](const std::string& name, const Run& run)
    {
      const double t1 = run.Error * run.Error * run.Seconds / 1e-4 * scale;
      std::printf("| %s | %s | %.0f | %.1f | %.4f | %.3g | %.0f s |\n", scene.Name.c_str(),
        name.c_str(), run.Spp, run.Seconds, run.Error, run.Efficiency(), t1);
      std::fflush(stdout);
    };
    // "all": the defaults (every technique that is on by default).
    auto defaults = [&](nimbus::PathTracingSettings& s)
    {
      for (const Technique& t : techniques)
      {
        t.Set(s, t.OnByDefault);
      }
    };
    const Run all = render(defaults);
    report("all (defaults)", all);
    const Run none = render(
      [&](nimbus::PathTracingSettings& s)
      {
        for (const Technique& t : techniques)
          t.Set(s, false);
      });
    report("none", none);
    std::printf("| %s | **defaults vs none** | | | | %.2fx | |\n", scene.Name.c_str(),
      all.Efficiency() / none.Efficiency());
    for (const Technique& technique : techniques)
    {
      if (!technique.OnByDefault)
      {
        const Run plus = render(
          [&](nimbus::PathTracingSettings& s)
          {
            defaults(s);
            technique.Set(s, true);
          });
        report(std::string("defaults + ") + technique.Name, plus);
        std::printf("| %s | **%s speed-up** | | | | defaults+it/defaults %.2fx | |\n",
          scene.Name.c_str(), technique.Name, plus.Efficiency() / all.Efficiency());
        std::fflush(stdout);
        continue;
      }
      const Run without = render(
        [&](nimbus::PathTracingSettings& s)
        {
          defaults(s);
          technique.Set(s, false);
        });
      report(std::string("defaults - ") + technique.Name, without);
      const Run only = render(
        [&](nimbus::PathTracingSettings& s)
        {
          for (const Technique& t : techniques)
            t.Set(s, false);
          technique.Set(s, true);
        });
      report(std::string("only ") + technique.Name, only);
      std::printf("| %s | **%s speed-up** | | | | defaults/without %.2fx, only/none %.2fx | |\n",
        scene.Name.c_str(), technique.Name, all.Efficiency() / without.Efficiency(),
        only.Efficiency() / none.Efficiency());
      std::fflush(stdout);
    }
  }
  return 0;
}
