#pragma once
// The local stencils of structure3d.hpp's discrete elastic rod, written once for any scalar: plain
// double (energies for the line search) and Dual2<N> (value, exact gradient and Hessian by forward
// second-order automatic differentiation, for Newton). Private to the core; tested through
// test_structure3d.cpp (finite differences of the assembled gradient and Hessian).
#include <Eigen/Core>
#include <cmath>

#include "wiresculpt/geometry.hpp"

namespace wiresculpt::detail {

/// A number with its gradient and Hessian with respect to N inputs.
template <int N>
struct Dual2 {
  using Grad = Eigen::Matrix<double, N, 1>;
  using Hess = Eigen::Matrix<double, N, N>;
  double v = 0.0;
  Grad g = Grad::Zero();
  Hess h = Hess::Zero();

  Dual2() = default;
  Dual2(double value) : v(value) {}  // NOLINT: constants mix freely with variables
  static Dual2 variable(double value, int i) {
    Dual2 d(value);
    d.g(i) = 1.0;
    return d;
  }
};

template <int N>
Dual2<N> operator+(const Dual2<N>& a, const Dual2<N>& b) {
  Dual2<N> r;
  r.v = a.v + b.v, r.g = a.g + b.g, r.h = a.h + b.h;
  return r;
}
template <int N>
Dual2<N> operator-(const Dual2<N>& a, const Dual2<N>& b) {
  Dual2<N> r;
  r.v = a.v - b.v, r.g = a.g - b.g, r.h = a.h - b.h;
  return r;
}
template <int N>
Dual2<N> operator-(const Dual2<N>& a) {
  Dual2<N> r;
  r.v = -a.v, r.g = -a.g, r.h = -a.h;
  return r;
}
template <int N>
Dual2<N> operator*(const Dual2<N>& a, const Dual2<N>& b) {
  Dual2<N> r;
  r.v = a.v * b.v;
  r.g = a.v * b.g + b.v * a.g;
  r.h = a.v * b.h + b.v * a.h + a.g * b.g.transpose() + b.g * a.g.transpose();
  return r;
}
template <int N>
Dual2<N> operator*(double s, const Dual2<N>& a) {
  Dual2<N> r;
  r.v = s * a.v, r.g = s * a.g, r.h = s * a.h;
  return r;
}
template <int N>
Dual2<N> operator*(const Dual2<N>& a, double s) {
  return s * a;
}
template <int N>
Dual2<N> operator+(const Dual2<N>& a, double s) {
  Dual2<N> r = a;
  r.v += s;
  return r;
}
template <int N>
Dual2<N> operator-(const Dual2<N>& a, double s) {
  return a + (-s);
}
/// f(a) from f(a.v), f'(a.v), f''(a.v): the chain rule to second order.
template <int N>
Dual2<N> chain(const Dual2<N>& a, double f, double df, double ddf) {
  Dual2<N> r;
  r.v = f;
  r.g = df * a.g;
  r.h = df * a.h + ddf * a.g * a.g.transpose();
  return r;
}
template <int N>
Dual2<N> operator/(const Dual2<N>& a, const Dual2<N>& b) {
  const double inv = 1.0 / b.v;
  return a * chain(b, inv, -inv * inv, 2.0 * inv * inv * inv);
}
template <int N>
Dual2<N> sqrt(const Dual2<N>& a) {
  const double s = std::sqrt(a.v);
  return chain(a, s, 0.5 / s, -0.25 / (s * a.v));
}
template <int N>
Dual2<N> sin(const Dual2<N>& a) {
  return chain(a, std::sin(a.v), std::cos(a.v), -std::sin(a.v));
}
template <int N>
Dual2<N> cos(const Dual2<N>& a) {
  return chain(a, std::cos(a.v), -std::sin(a.v), -std::cos(a.v));
}
/// atan2(y, x) = φ0 + atan(u), u = (x0 y - y0 x) / (x0 x + y0 y), exact near (x0, y0), where u = 0
/// and atan has derivatives 1 and 0.
template <int N>
Dual2<N> atan2(const Dual2<N>& y, const Dual2<N>& x) {
  const double phi0 = std::atan2(y.v, x.v);
  Dual2<N> u = (x.v * y - y.v * x) / (x.v * x + y.v * y);
  u.v = phi0;
  return u;
}
inline double value(double a) { return a; }
template <int N>
double value(const Dual2<N>& a) {
  return a.v;
}

/// A 3-vector of any scalar.
template <class T>
struct V3 {
  T x, y, z;
};
template <class T>
V3<T> constant(const Vec3& v) {
  return {T(v.x()), T(v.y()), T(v.z())};
}
template <class T>
V3<T> operator+(const V3<T>& a, const V3<T>& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class T>
V3<T> operator-(const V3<T>& a, const V3<T>& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class T, class S>
V3<T> scale(const S& s, const V3<T>& a) {
  return {s * a.x, s * a.y, s * a.z};
}
template <class T>
T dot(const V3<T>& a, const V3<T>& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class T>
V3<T> cross(const V3<T>& a, const V3<T>& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class T>
T norm(const V3<T>& a) {
  using std::sqrt;
  return sqrt(dot(a, a));
}
template <class T>
V3<T> unit(const V3<T>& a) {
  const T inv = T(1.0) / norm(a);
  return scale(inv, a);
}
inline Vec3 eigen(const V3<double>& a) { return {a.x, a.y, a.z}; }

/// The rotation taking unit a to unit b about a × b, applied to v (parallel transport):
/// R v = (a·b) v + (a×b)×v + ((a×b)·v)(a×b)/(1 + a·b), smooth where a = b.
template <class T>
V3<T> transport(const V3<T>& a, const V3<T>& b, const V3<T>& v) {
  const T c = dot(a, b);
  const V3<T> w = cross(a, b);
  return scale(c, v) + cross(w, v) + scale(dot(w, v) / (c + 1.0), w);
}

/// The reference frame of an edge between Newton steps: its tangent and first director then.
struct EdgeFrame {
  Vec3 t = Vec3::UnitX();
  Vec3 d1 = Vec3::UnitY();
};

/// What a bend-twist stencil at node k needs besides its unknowns.
struct BendTwistData {
  EdgeFrame frame0, frame1;     ///< of edges k-1 and k
  Eigen::Vector2d rest0, rest1;  ///< ω̄_k^{k-1}, ω̄_k^k
  double twist_offset = 0.0;    ///< 2π multiple making the reference twist continuous
  double voronoi = 1.0;         ///< l̄_k, metres
  double EI = 1.0, GJ = 1.0;
};

/// Material directors (m1, m2) of an edge of tangent t whose reference frame was `frame`.
template <class T>
void material_frame(const V3<T>& t, const EdgeFrame& frame, const T& theta, V3<T>& m1, V3<T>& m2) {
  using std::cos;
  using std::sin;
  const V3<T> d1 = transport(constant<T>(frame.t), t, constant<T>(frame.d1));
  const V3<T> d2 = cross(t, d1);
  const T c = cos(theta), s = sin(theta);
  m1 = scale(c, d1) + scale(s, d2);
  m2 = scale(c, d2) - scale(s, d1);
}

/// The reference twist at a node: the signed angle about t1 from d1 of edge 0 transported onto
/// t1 to d1 of edge 1 (without the 2π offset).
template <class T>
T reference_twist(const V3<T>& t0, const V3<T>& t1, const EdgeFrame& f0, const EdgeFrame& f1) {
  using std::atan2;
  const V3<T> a = transport(constant<T>(f0.t), t0, constant<T>(f0.d1));
  const V3<T> b = transport(constant<T>(f1.t), t1, constant<T>(f1.d1));
  const V3<T> u = transport(t0, t1, a);
  return atan2(dot(cross(u, b), t1), dot(u, b));
}

/// E_bend + E_twist at one node from its three nodes and two edge angles.
template <class T>
T bend_twist_energy(const V3<T>& x0, const V3<T>& x1, const V3<T>& x2, const T& th0, const T& th1,
                    const BendTwistData& d) {
  const V3<T> t0 = unit(x1 - x0), t1 = unit(x2 - x1);
  V3<T> m1a, m2a, m1b, m2b;
  material_frame(t0, d.frame0, th0, m1a, m2a);
  material_frame(t1, d.frame1, th1, m1b, m2b);
  const V3<T> kb = scale(T(2.0) / (dot(t0, t1) + 1.0), cross(t0, t1));
  const T a1 = dot(kb, m2a) - d.rest0(0), a2 = -dot(kb, m1a) - d.rest0(1);
  const T b1 = dot(kb, m2b) - d.rest1(0), b2 = -dot(kb, m1b) - d.rest1(1);
  const T bend = (0.5 * d.EI / d.voronoi) * (a1 * a1 + a2 * a2 + b1 * b1 + b2 * b2);
  const T m = th1 - th0 + reference_twist(t0, t1, d.frame0, d.frame1) + d.twist_offset;
  return bend + (d.GJ / d.voronoi) * (m * m);
}

/// E_stretch of one edge of rest length `rest` and axial stiffness EA.
template <class T>
T stretch_energy(const V3<T>& x0, const V3<T>& x1, double rest, double EA) {
  const T strain = norm(x1 - x0) * (1.0 / rest) + (-1.0);
  return (0.5 * EA * rest) * (strain * strain);
}

}  // namespace wiresculpt::detail
