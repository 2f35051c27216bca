// A contact law wrapped for `verdem verify --code` (docs/code-interface.md).
//
//     g++ -std=c++17 -O2 -o law law.cpp
//     ./law CASE.toml MOTION.csv --out FORCES.csv
//
// reads the law's parameters and the radii from CASE.toml and the motion of the two spheres
// from MOTION.csv, and writes the force and torques on each sphere at every row to FORCES.csv.
// C++17, standard library only.
//
// `contact_force` is verdem's objective law: a linear spring-dashpot normal force, a
// tangential spring that turns with the contact, a tangential dashpot and a Coulomb slider. To
// judge your own law, replace its body by a call into your code and keep its history in
// `State`; then run `verdem verify --code ./law --convention NAME` with the convention your
// law claims.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

using Vec = std::array<double, 3>;

Vec operator+(Vec a, Vec b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
Vec operator-(Vec a, Vec b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec operator*(double s, Vec a) { return {s * a[0], s * a[1], s * a[2]}; }
double dot(Vec a, Vec b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec cross(Vec a, Vec b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(Vec a) { return std::sqrt(dot(a, a)); }

// The parameters of the case's [contact] table.
struct Law {
    double kn, gamman, kt, gammat, mu;
    bool clip_normal;
};

// What a contact keeps from row to row: the tangential spring (length); its elastic force on
// sphere 2 is -kt * spring.
struct State {
    Vec spring{0.0, 0.0, 0.0};
};

// The force on sphere 2 (lab frame) and its normal part fn, for overlapping spheres of radii
// r1, r2: x = x2 - x1 now and x_old at the previous row, v = v2 - v1 and the spins w1, w2 over
// the step dt.
Vec contact_force(const Law& c, double r1, double r2, Vec x, Vec x_old, Vec v, Vec w1, Vec w2,
                  double dt, State& state, double& fn) {
    double dist = norm(x);
    Vec n = (1.0 / dist) * x;
    fn = c.kn * (r1 + r2 - dist) - c.gamman * dot(v, n);
    if (c.clip_normal) fn = std::max(fn, 0.0);
    if (c.mu == 0.0) return fn * n;
    Vec& spring = state.spring;
    // turn the spring with the contact: tilt it from the previous normal to n, then twist it
    // about n by the mean spin about the step's middle normal m
    Vec n_old = (1.0 / norm(x_old)) * x_old;
    Vec m = (1.0 / norm(n_old + n)) * (n_old + n);
    spring = spring - (dot(spring, n) / (1.0 + dot(n_old, n))) * (n_old + n);
    double phi = 0.5 * dt * dot(w1 + w2, m);
    spring = std::cos(phi) * spring + std::sin(phi) * cross(n, spring);
    // stretch it by the slip: the relative velocity at the contact less that of a rigid motion
    // of the pair, taken at m, then in the tangent plane of n
    Vec slip = ((r1 + r2) / dist) * v - cross(r2 * w2 + r1 * w1, m);
    slip = slip - dot(slip, m) * m;
    slip = slip - dot(slip, n) * n;
    spring = spring + dt * slip;
    // Coulomb: the elastic force is capped at mu |fn| (the spring slides back to it), then the
    // dashpot is added and the total capped again
    double limit = c.mu * std::abs(fn);
    Vec elastic = -c.kt * spring;
    if (norm(elastic) > limit) {
        elastic = (limit / norm(elastic)) * elastic;
        spring = (-1.0 / c.kt) * elastic;
    }
    Vec ft = elastic - c.gammat * slip;
    if (norm(ft) > limit) ft = (limit / norm(ft)) * ft;
    return fn * n + ft;
}

// The rotation vector (axis times angle) taking orientation p to q, unit quaternions
// (w, x, y, z): that of q p^-1. The angle is 2 atan2(|xyz|, |w|), not 2 acos(w), which loses
// half the digits for the small turns of one row.
Vec turn(const double* q, const double* p) {
    double w = q[0], x = q[1], y = q[2], z = q[3];
    double pw = p[0], px = -p[1], py = -p[2], pz = -p[3];
    double rw = w * pw - x * px - y * py - z * pz;
    Vec r{w * px + x * pw + y * pz - z * py, w * py - x * pz + y * pw + z * px,
          w * pz + x * py - y * px + z * pw};
    double s = norm(r);
    if (s == 0.0) return {0.0, 0.0, 0.0};
    return (std::copysign(2.0 * std::atan2(s, std::abs(rw)) / s, rw)) * r;
}

std::string trim(const std::string& s) {
    auto a = s.find_first_not_of(" \t\r");
    auto b = s.find_last_not_of(" \t\r");
    return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

// The [contact] values and the radii of the [[scene.sphere]] tables: all this needs of TOML
// (numbers and booleans, one `key = value` a line).
void read_case(const std::string& path, Law& law, std::vector<double>& radii) {
    std::ifstream f(path);
    if (!f) throw std::runtime_error(path + ": cannot be read");
    std::map<std::string, std::string> contact;
    std::string line, table;
    while (std::getline(f, line)) {
        line = trim(line.substr(0, line.find('#')));
        if (line.empty()) continue;
        if (line[0] == '[') {
            table = line;
            if (table == "[[scene.sphere]]") radii.push_back(0.0);
            continue;
        }
        auto eq = line.find('=');
        if (eq == std::string::npos) continue;
        std::string key = trim(line.substr(0, eq)), value = trim(line.substr(eq + 1));
        if (table == "[contact]") contact[key] = value;
        if (table == "[[scene.sphere]]" && key == "radius") radii.back() = std::stod(value);
    }
    auto number = [&](const char* key) {
        if (!contact.count(key)) throw std::runtime_error(path + ": no [contact] " + key);
        return std::stod(contact[key]);
    };
    law = {number("kn"), number("gamman"), number("kt"), number("gammat"), number("mu"),
           contact["clip_normal"] == "true"};
    if (radii.size() != 2) throw std::runtime_error(path + ": not two [[scene.sphere]]");
}

const char* MOTION =
    "t,x1,y1,z1,qw1,qx1,qy1,qz1,vx1,vy1,vz1,wx1,wy1,wz1,"
    "x2,y2,z2,qw2,qx2,qy2,qz2,vx2,vy2,vz2,wx2,wy2,wz2";

std::vector<std::array<double, 27>> read_motion(const std::string& path) {
    std::ifstream f(path);
    if (!f) throw std::runtime_error(path + ": cannot be read");
    std::vector<std::array<double, 27>> rows;
    std::string line;
    bool header = true;
    while (std::getline(f, line)) {
        line = trim(line);
        if (line.empty() || line[0] == '#') continue;
        if (header) {
            if (line != MOTION) throw std::runtime_error(path + ": the header is not " + MOTION);
            header = false;
            continue;
        }
        std::array<double, 27> row;
        std::istringstream cells(line);
        std::string cell;
        for (double& x : row) {
            if (!std::getline(cells, cell, ',')) throw std::runtime_error(path + ": short row");
            x = std::stod(cell);
        }
        rows.push_back(row);
    }
    return rows;
}

int main(int argc, char** argv) {
    if (argc != 5 || std::string(argv[3]) != "--out") {
        std::cerr << "usage: " << argv[0] << " CASE.toml MOTION.csv --out FORCES.csv\n";
        return 2;
    }
    try {
        Law law;
        std::vector<double> radii;
        read_case(argv[1], law, radii);
        double r1 = radii[0], r2 = radii[1];
        auto rows = read_motion(argv[2]);

        std::ofstream out(argv[4]);
        out << "t,fx1,fy1,fz1,tx1,ty1,tz1,fx2,fy2,fz2,tx2,ty2,tz2,delta,fn,ft\n";
        State state;
        for (size_t k = 0; k < rows.size(); ++k) {
            const double* row = rows[k].data();
            Vec x1{row[1], row[2], row[3]}, x2{row[14], row[15], row[16]};
            Vec x = x2 - x1, x_old = x;
            // the first row has no step: its own velocities
            double dt = 0.0;
            Vec v1{row[8], row[9], row[10]}, w1{row[11], row[12], row[13]};
            Vec v2{row[21], row[22], row[23]}, w2{row[24], row[25], row[26]};
            if (k > 0) {
                // the step from the previous row: the velocities of its positions and
                // orientations
                const double* prev = rows[k - 1].data();
                dt = row[0] - prev[0];
                Vec p1{prev[1], prev[2], prev[3]}, p2{prev[14], prev[15], prev[16]};
                v1 = (1.0 / dt) * (x1 - p1);
                v2 = (1.0 / dt) * (x2 - p2);
                w1 = (1.0 / dt) * turn(row + 4, prev + 4);
                w2 = (1.0 / dt) * turn(row + 17, prev + 17);
                x_old = p2 - p1;
            }
            double delta = r1 + r2 - norm(x);
            std::vector<double> cols{row[0]};
            if (delta <= 0.0) {
                state = State{};  // apart: no force, and the contact's history is forgotten
                cols.insert(cols.end(), 12, 0.0);
                cols.insert(cols.end(), {delta, 0.0, 0.0});
            } else {
                double fn;
                Vec f2 = contact_force(law, r1, r2, x, x_old, v2 - v1, w1, w2, dt, state, fn);
                Vec f1 = -1.0 * f2;
                // lever arms from each centre to the contact point in the middle of the overlap
                Vec n = (1.0 / norm(x)) * x;
                Vec arm2 = -(r2 - 0.5 * delta) * n;
                Vec arm1 = x + arm2;
                double ft = norm(f2 - dot(f2, n) * n);
                for (Vec part : {f1, cross(arm1, f1), f2, cross(arm2, f2)})
                    cols.insert(cols.end(), part.begin(), part.end());
                cols.insert(cols.end(), {delta, fn, ft});
            }
            for (size_t i = 0; i < cols.size(); ++i) {
                // 17 significant digits read back to the same double
                char cell[32];
                std::snprintf(cell, sizeof cell, "%.17g", cols[i]);
                out << (i ? "," : "") << cell;
            }
            out << '\n';
        }
        if (!out) throw std::runtime_error(std::string(argv[4]) + ": cannot be written");
    } catch (const std::exception& e) {
        std::cerr << argv[0] << ": " << e.what() << '\n';
        return 1;
    }
}
