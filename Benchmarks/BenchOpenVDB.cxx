// Timing of the OpenVDB writer and reader (plain main(), prints a table).
//
//   BenchOpenVDB [n] [repeats] [directory]      (defaults: 256 3 /tmp)
//
// Fields on an n^3 image (spacing 0.5, origin (-10, 5, 20)):
//   dense   every voxel active (0.5 + 0.4 sin...; never the background 0)
//   sparse  a ball holding ~10 % of the voxels (radius 0.2879 n), 0 elsewhere
//   vec3    3-component dense field (Vec3SGrid)
// Each case is written by vtkNimbusOpenVDBWriter (Blosc on, then off) and read back by
// vtkNimbusOpenVDBReader; times are wall-clock medians of `repeats` runs, including the
// temporary-file rename and OpenVDB's threaded dense<->sparse copies. MB/s is the dense
// float payload (points x components x 4 bytes, 1 MB = 10^6 bytes) per second: of the
// n^3 input image for writes, of the image read back (the active bounding box, smaller
// for the sparse ball) for reads. The read is checked against the
// written values (a mismatch aborts).
#include "vtkNimbusOpenVDBReader.h"
#include "vtkNimbusOpenVDBWriter.h"

#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPointData.h"

#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

namespace
{
double Now()
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double Median(std::vector<double> v)
{
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

vtkSmartPointer<vtkImageData> MakeImage(int n, const std::string& kind)
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(n, n, n);
  image->SetSpacing(0.5, 0.5, 0.5);
  image->SetOrigin(-10, 5, 20);
  const int comps = kind == "vec3" ? 3 : 1;
  vtkNew<vtkFloatArray> a;
  a->SetName(kind == "vec3" ? "velocity" : "density");
  a->SetNumberOfComponents(comps);
  a->SetNumberOfTuples(vtkIdType(n) * n * n);
  float* p = a->GetPointer(0);
  const double c = 0.5 * (n - 1), r = 0.2879 * n; // (4/3) pi r^3 = 0.1 n^3
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i, p += comps)
      {
        const float v = 0.5f + 0.4f * std::sin(0.05f * i + 0.03f * j) * std::cos(0.07f * k);
        if (kind == "sparse")
        {
          const double d2 = (i - c) * (i - c) + (j - c) * (j - c) + (k - c) * (k - c);
          p[0] = d2 <= r * r ? v : 0.0f;
        }
        else
        {
          for (int m = 0; m < comps; ++m)
          {
            p[m] = v + 0.1f * m;
          }
        }
      }
  image->GetPointData()->AddArray(a);
  return image;
}

long FileSize(const std::string& path)
{
  struct stat st;
  return ::stat(path.c_str(), &st) == 0 ? long(st.st_size) : -1;
}
}

int main(int argc, char* argv[])
{
  const int n = argc > 1 ? std::atoi(argv[1]) : 256;
  const int repeats = argc > 2 ? std::max(1, std::atoi(argv[2])) : 3;
  const std::string dir = argc > 3 ? argv[3] : "/tmp";
  std::printf("OpenVDB write/read of a %d^3 image, median of %d runs, %u hardware threads\n", n,
    repeats, std::thread::hardware_concurrency());
  std::printf("%-7s %-6s %10s %10s %10s %10s %10s %10s %10s\n", "field", "blosc", "active",
    "write s", "write MB/s", "read pts", "read s", "read MB/s", "file MB");
  for (const std::string kind : { "dense", "sparse", "vec3" })
  {
    auto image = MakeImage(n, kind);
    vtkDataArray* original = image->GetPointData()->GetArray(0);
    const double payload = double(original->GetNumberOfValues()) * 4.0 / 1e6;
    for (const bool blosc : { true, false })
    {
      const std::string path = dir + "/nimbus-bench-" + kind + (blosc ? "-blosc" : "-raw") + ".vdb";
      std::vector<double> writes, reads;
      vtkIdType active = 0, readPoints = 0;
      for (int r = 0; r < repeats; ++r)
      {
        vtkNew<vtkNimbusOpenVDBWriter> writer;
        writer->SetInputData(image);
        writer->SetFileName(path.c_str());
        writer->SetCompress(blosc);
        double t0 = Now();
        if (!writer->Write())
        {
          std::fprintf(stderr, "write failed\n");
          return 1;
        }
        writes.push_back(Now() - t0);
        active = writer->GetNumberOfActiveVoxels();

        vtkNew<vtkNimbusOpenVDBReader> reader;
        reader->SetFileName(path.c_str());
        reader->SetBoundsGrid(original->GetName());
        t0 = Now();
        reader->Update();
        reads.push_back(Now() - t0);
        vtkImageData* out = reader->GetOutput();
        readPoints = out->GetNumberOfPoints();
        vtkDataArray* back = out->GetPointData()->GetArray(original->GetName());
        if (!back)
        {
          std::fprintf(stderr, "read failed\n");
          return 1;
        }
        // Check: every read point equals the original at the same index.
        int ext[6];
        out->GetExtent(ext);
        for (int k = ext[4]; k <= ext[5]; k += 7)
          for (int j = ext[2]; j <= ext[3]; j += 5)
            for (int i = ext[0]; i <= ext[1]; ++i)
            {
              int ijk[3] = { i, j, k };
              for (int m = 0; m < original->GetNumberOfComponents(); ++m)
              {
                if (back->GetComponent(out->ComputePointId(ijk), m) !=
                  original->GetComponent(image->ComputePointId(ijk), m))
                {
                  std::fprintf(stderr, "mismatch at %d %d %d\n", i, j, k);
                  return 1;
                }
              }
            }
      }
      const double w = Median(writes), rd = Median(reads);
      const double readPayload = double(readPoints) * original->GetNumberOfComponents() * 4.0 / 1e6;
      std::printf("%-7s %-6s %10lld %10.3f %10.1f %10lld %10.3f %10.1f %10.2f\n", kind.c_str(),
        blosc ? "on" : "off", static_cast<long long>(active), w, payload / w,
        static_cast<long long>(readPoints), rd, readPayload / rd, FileSize(path) / 1e6);
      std::remove(path.c_str());
    }
  }
  return 0;
}
