// FCL 0.7 on one mesh pair, by the protocol of `examples/pair_queries.rs`, so that both
// engines run on the same meshes and poses in the same session (README in this folder).
//
//   fcl_pairs MESH1.obj MESH2.obj TRANSFORMS.txt [--scale1 S] [--scale2 S] [--center]
//             [--repeats K] [--bv obbrss|rss|obb|kios|aabb] [--dump DIR]
//   fcl_pairs --write-poses N XMIN YMIN ZMIN XMAX YMAX ZMAX > TRANSFORMS.txt
//
// Mesh 1 takes each transform (row-major 3x3 rotation, then the translation; `#` comment
// lines, then the count), mesh 2 stays at identity; `--scale` multiplies a mesh's vertices
// and `--center` then moves its bounding-box centre to the origin. The BVHs (FCL's own
// builder, its default split rule) are built once, outside the timing. Per transform each
// query runs twice to warm up and is then timed over K runs (default 5): its time is their
// mean. Queries: `collide_bool` (one contact, no contact data), `collide_all` (every
// intersecting triangle pair), `distance` (exact: FCL's default rel_err = abs_err = 0).
// OBB and AABB trees answer no distance query in FCL: their distance row is skipped.
//
// `--write-poses` writes N transforms as FCL's own tests draw them (C `rand()` from seed 1:
// a uniform translation in the box, three uniform angles in [0, 2π) composed as FCL's test
// utilities compose Euler angles), in the transforms file's format.
//
// stdout: one TSV row per query, `query n mean_us median_us p95_us max_us colliding
// tri_pairs mean_dist`, as pair_queries prints it. `--dump DIR` writes DIR/fcl.tsv:
// `i collide_bool collide_all contacts tri_pairs distance`.

#include <fcl/fcl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace {

struct Mesh {
  std::vector<fcl::Vector3d> vertices;
  std::vector<fcl::Triangle> triangles;
};

// Vertices and faces of an OBJ file (`v`, and `f` with `i`, `i/t`, `i//n` or `i/t/n`
// indices, 1-based or negative); polygons are fanned into triangles.
Mesh load_obj(const std::string& path, double scale, bool center) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  Mesh mesh;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string tag;
    words >> tag;
    if (tag == "v") {
      double x, y, z;
      words >> x >> y >> z;
      mesh.vertices.emplace_back(x * scale, y * scale, z * scale);
    } else if (tag == "f") {
      std::vector<long> face;
      std::string word;
      while (words >> word) {
        long i = std::stol(word.substr(0, word.find('/')));
        face.push_back(i > 0 ? i - 1 : static_cast<long>(mesh.vertices.size()) + i);
      }
      for (size_t k = 1; k + 1 < face.size(); ++k)
        mesh.triangles.emplace_back(face[0], face[k], face[k + 1]);
    }
  }
  if (center && !mesh.vertices.empty()) {
    fcl::Vector3d low = mesh.vertices[0], high = mesh.vertices[0];
    for (const auto& v : mesh.vertices) {
      low = low.cwiseMin(v);
      high = high.cwiseMax(v);
    }
    const fcl::Vector3d middle = 0.5 * (low + high);
    for (auto& v : mesh.vertices) v -= middle;
  }
  return mesh;
}

std::vector<fcl::Transform3d> load_transforms(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::string line;
  long count = -1;
  std::vector<fcl::Transform3d> out;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream words(line);
    if (count < 0) {
      words >> count;
      continue;
    }
    double r[9], t[3];
    for (double& x : r) words >> x;
    for (double& x : t) words >> x;
    fcl::Matrix3d rotation;
    rotation << r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8];
    fcl::Transform3d pose = fcl::Transform3d::Identity();
    pose.linear() = rotation;
    pose.translation() = fcl::Vector3d(t[0], t[1], t[2]);
    out.push_back(pose);
    if (static_cast<long>(out.size()) == count) break;
  }
  if (static_cast<long>(out.size()) != count) throw std::runtime_error("short transforms file");
  return out;
}

// Mean microseconds of `repeats` runs of `query` after two warm-up runs; `last` gets the
// last run's answer.
template <typename Query, typename Answer>
double time_us(int repeats, Query query, Answer& last) {
  for (int i = 0; i < 2; ++i) last = query();
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < repeats; ++i) last = query();
  const std::chrono::duration<double, std::micro> spent = std::chrono::steady_clock::now() - start;
  return spent.count() / repeats;
}

std::string summary(const char* name, std::vector<double> times, size_t colliding,
                    const std::string& pairs, const std::string& dist) {
  std::sort(times.begin(), times.end());
  const size_t n = times.size();
  double mean = 0;
  for (double t : times) mean += t;
  mean /= n;
  const double median = n % 2 ? times[n / 2] : 0.5 * (times[n / 2 - 1] + times[n / 2]);
  const size_t p95 = std::min(n, std::max<size_t>(1, std::ceil(0.95 * n))) - 1;
  char row[256];
  std::snprintf(row, sizeof row, "%s\t%zu\t%.2f\t%.2f\t%.2f\t%.2f\t%zu\t%s\t%s", name, n, mean,
                median, times[p95], times[n - 1], colliding, pairs.c_str(), dist.c_str());
  return row;
}

struct Runs {
  std::vector<double> time_bool, time_all, time_distance, distance;
  std::vector<int> hit;
  std::vector<size_t> pairs;
};

template <typename BV>
Runs run(const Mesh& m1, const Mesh& m2, const std::vector<fcl::Transform3d>& poses, int repeats,
         bool with_distance) {
  auto model = [](const Mesh& m) {
    auto bvh = std::make_shared<fcl::BVHModel<BV>>();
    bvh->beginModel();
    bvh->addSubModel(m.vertices, m.triangles);
    bvh->endModel();
    return bvh;
  };
  auto g1 = model(m1), g2 = model(m2);
  const fcl::Transform3d identity = fcl::Transform3d::Identity();
  Runs runs;
  for (const auto& pose : poses) {
    fcl::CollisionObjectd o1(g1, pose), o2(g2, identity);
    bool hit = false;
    runs.time_bool.push_back(time_us(repeats, [&] {
      fcl::CollisionRequestd request(1, false);
      fcl::CollisionResultd result;
      fcl::collide(&o1, &o2, request, result);
      return result.isCollision();
    }, hit));
    runs.hit.push_back(hit);
    size_t pairs = 0;
    runs.time_all.push_back(time_us(repeats, [&] {
      fcl::CollisionRequestd request(std::numeric_limits<size_t>::max(), false);
      fcl::CollisionResultd result;
      fcl::collide(&o1, &o2, request, result);
      return result.numContacts();
    }, pairs));
    runs.pairs.push_back(pairs);
    if (with_distance) {
      double d = 0;
      runs.time_distance.push_back(time_us(repeats, [&] {
        fcl::DistanceRequestd request;
        fcl::DistanceResultd result;
        fcl::distance(&o1, &o2, request, result);
        return result.min_distance;
      }, d));
      runs.distance.push_back(std::max(d, 0.0));
    }
  }
  return runs;
}

// N transforms in the transforms file's format, drawn as the module comment says.
void write_poses(long n, const double extents[6]) {
  std::srand(1);
  auto uniform = [](double low, double high) {
    return std::rand() / (static_cast<double>(RAND_MAX) + 1) * (high - low) + low;
  };
  std::printf("# %ld transforms: translation uniform in [%g, %g] x [%g, %g] x [%g, %g], "
              "rotation from three uniform angles (C rand(), seed 1)\n%ld\n",
              n, extents[0], extents[3], extents[1], extents[4], extents[2], extents[5], n);
  const double two_pi = 2 * 3.14159265358979323846;
  for (long i = 0; i < n; ++i) {
    const double x = uniform(extents[0], extents[3]), y = uniform(extents[1], extents[4]),
                 z = uniform(extents[2], extents[5]);
    const double a = uniform(0, two_pi), b = uniform(0, two_pi), c = uniform(0, two_pi);
    const double c1 = std::cos(a), c2 = std::cos(b), c3 = std::cos(c);
    const double s1 = std::sin(a), s2 = std::sin(b), s3 = std::sin(c);
    const double r[9] = {c1 * c2, -c2 * s1, s2,
                         c3 * s1 + c1 * s2 * s3, c1 * c3 - s1 * s2 * s3, -c2 * s3,
                         s1 * s3 - c1 * c3 * s2, c3 * s1 * s2 + c1 * s3, c2 * c3};
    for (double v : r) std::printf("%.17g ", v);
    std::printf("%.17g %.17g %.17g\n", x, y, z);
  }
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc == 9 && std::string(argv[1]) == "--write-poses") {
      double extents[6];
      for (int k = 0; k < 6; ++k) extents[k] = std::stod(argv[3 + k]);
      write_poses(std::stol(argv[2]), extents);
      return 0;
    }
    std::vector<std::string> positional;
    double scales[2] = {1, 1};
    bool center = false;
    int repeats = 5;
    std::string bv = "obbrss", dump;
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      auto value = [&] {
        if (i + 1 >= argc) throw std::runtime_error(arg + " needs a value");
        return std::string(argv[++i]);
      };
      if (arg == "--scale1") scales[0] = std::stod(value());
      else if (arg == "--scale2") scales[1] = std::stod(value());
      else if (arg == "--center") center = true;
      else if (arg == "--repeats") repeats = std::max(1, std::stoi(value()));
      else if (arg == "--bv") bv = value();
      else if (arg == "--dump") dump = value();
      else if (arg.rfind("--", 0) == 0) throw std::runtime_error("unknown option " + arg);
      else positional.push_back(arg);
    }
    if (positional.size() != 3)
      throw std::runtime_error("usage: fcl_pairs MESH1 MESH2 TRANSFORMS [options]");
    const Mesh m1 = load_obj(positional[0], scales[0], center);
    const Mesh m2 = load_obj(positional[1], scales[1], center);
    const auto poses = load_transforms(positional[2]);
    Runs runs;
    if (bv == "obbrss") runs = run<fcl::OBBRSSd>(m1, m2, poses, repeats, true);
    else if (bv == "rss") runs = run<fcl::RSSd>(m1, m2, poses, repeats, true);
    else if (bv == "kios") runs = run<fcl::kIOSd>(m1, m2, poses, repeats, true);
    else if (bv == "obb") runs = run<fcl::OBBd>(m1, m2, poses, repeats, false);
    else if (bv == "aabb") runs = run<fcl::AABBd>(m1, m2, poses, repeats, false);
    else throw std::runtime_error("unknown BV " + bv + " (obbrss, rss, kios, obb, aabb)");
    std::cerr << m1.triangles.size() << " + " << m2.triangles.size() << " triangles; FCL " << bv
              << " trees\n";
    const size_t colliding = std::count(runs.hit.begin(), runs.hit.end(), 1);
    size_t touching = 0, total = 0;
    for (size_t p : runs.pairs) {
      touching += p > 0;
      total += p;
    }
    std::cout << "query\tn\tmean_us\tmedian_us\tp95_us\tmax_us\tcolliding\ttri_pairs\tmean_dist\n";
    std::cout << summary("collide_bool", runs.time_bool, colliding, "-", "-") << "\n";
    std::cout << summary("collide_all", runs.time_all, touching, std::to_string(total), "-") << "\n";
    if (!runs.distance.empty()) {
      double mean = 0;
      size_t zero = 0;
      for (double d : runs.distance) {
        mean += d;
        zero += d == 0;
      }
      char dist[64];
      std::snprintf(dist, sizeof dist, "%.6f", mean / runs.distance.size());
      std::cout << summary("distance", runs.time_distance, zero, "-", dist) << "\n";
    }
    if (!dump.empty()) {
      std::ofstream out(dump + "/fcl.tsv");
      out << "i\tcollide_bool\tcollide_all\tcontacts\ttri_pairs\tdistance\n";
      for (size_t i = 0; i < poses.size(); ++i) {
        char row[128];
        std::snprintf(row, sizeof row, "%zu\t%d\t%d\t%zu\t%zu\t%.16e\n", i, runs.hit[i],
                      runs.pairs[i] > 0, runs.pairs[i], runs.pairs[i],
                      runs.distance.empty() ? 0.0 : runs.distance[i]);
        out << row;
      }
    }
  } catch (const std::exception& e) {
    std::cerr << "fcl_pairs: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
