#pragma once
// A 3-vector with the operations the shared kernels need, each written with one fixed order of
// operations (physics.md §6): dot is ((x*x + y*y) + z*z), never a reassociated reduction.
#include "demmat/host_device.hpp"

namespace demmat {

template <class T>
struct Vec3 {
    T x{}, y{}, z{};
};

using Vec3d = Vec3<double>;

template <class T> DEMMAT_HD inline Vec3<T> operator+(const Vec3<T>& a, const Vec3<T>& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
template <class T> DEMMAT_HD inline Vec3<T> operator-(const Vec3<T>& a, const Vec3<T>& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
template <class T> DEMMAT_HD inline Vec3<T> operator-(const Vec3<T>& a) { return {-a.x, -a.y, -a.z}; }
template <class T> DEMMAT_HD inline Vec3<T> operator*(T s, const Vec3<T>& a) { return {s * a.x, s * a.y, s * a.z}; }
template <class T> DEMMAT_HD inline Vec3<T> operator/(const Vec3<T>& a, T s) { return {a.x / s, a.y / s, a.z / s}; }
template <class T> DEMMAT_HD inline Vec3<T>& operator+=(Vec3<T>& a, const Vec3<T>& b) { a.x += b.x; a.y += b.y; a.z += b.z; return a; }
template <class T> inline bool operator==(const Vec3<T>& a, const Vec3<T>& b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

template <class T> DEMMAT_HD inline T dot(const Vec3<T>& a, const Vec3<T>& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
template <class T> DEMMAT_HD inline Vec3<T> cross(const Vec3<T>& a, const Vec3<T>& b)
{
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

template <class T> inline T component(const Vec3<T>& a, int c) { return c == 0 ? a.x : (c == 1 ? a.y : a.z); }
template <class T> inline T& component(Vec3<T>& a, int c) { return c == 0 ? a.x : (c == 1 ? a.y : a.z); }

template <class U, class T> inline Vec3<U> cast(const Vec3<T>& a) { return {U(a.x), U(a.y), U(a.z)}; }

} // namespace demmat
