// pybind11 conversions shared by the binding sources: Vec3 / Spectrum <-> 3-sequences (tuples, lists,
// numpy arrays, Gf.Vec3f/d), Affine <-> (3,4) or (4,4) arrays in the core's column-vector convention
// (p' = M p; translation in the last column). A Gf.Matrix4d is row-vector (translation in the last
// row): the Python front end transposes it (volphoton.usdscene.affine_from_gf).
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cmath>

#include "core/math.h"

namespace pybind11 {
namespace detail {

inline bool loadThree(handle src, bool convert, double out[3]) {
    if (!src || PyUnicode_Check(src.ptr()) || PyBytes_Check(src.ptr()) || !PySequence_Check(src.ptr())) return false;
    Py_ssize_t n = PySequence_Size(src.ptr());
    if (n != 3) {
        if (n < 0) PyErr_Clear();
        return false;
    }
    for (Py_ssize_t i = 0; i < 3; ++i) {
        object item = reinterpret_steal<object>(PySequence_GetItem(src.ptr(), i));
        if (!item) {
            PyErr_Clear();
            return false;
        }
        make_caster<double> c;
        if (!c.load(item, convert)) return false;
        out[i] = cast_op<double>(c);
    }
    return true;
}

template <>
struct type_caster<volphoton::Vec3> {
    PYBIND11_TYPE_CASTER(volphoton::Vec3, const_name("tuple[float, float, float]"));
    bool load(handle src, bool convert) {
        double v[3];
        if (!loadThree(src, convert, v)) return false;
        value = volphoton::Vec3(v[0], v[1], v[2]);
        return true;
    }
    static handle cast(const volphoton::Vec3& v, return_value_policy, handle) {
        return make_tuple(v.x, v.y, v.z).release();
    }
};

/// A Spectrum also accepts a single number (grey).
template <>
struct type_caster<volphoton::Spectrum> {
    PYBIND11_TYPE_CASTER(volphoton::Spectrum, const_name("tuple[float, float, float]"));
    bool load(handle src, bool convert) {
        double v[3];
        if (loadThree(src, convert, v)) {
            value = volphoton::Spectrum(v[0], v[1], v[2]);
            return true;
        }
        if (src && (PyFloat_Check(src.ptr()) || PyLong_Check(src.ptr()))) {
            make_caster<double> c;
            if (!c.load(src, convert)) return false;
            value = volphoton::Spectrum(cast_op<double>(c));
            return true;
        }
        return false;
    }
    static handle cast(const volphoton::Spectrum& s, return_value_policy, handle) {
        return make_tuple(s[0], s[1], s[2]).release();
    }
};

template <>
struct type_caster<volphoton::Affine> {
    PYBIND11_TYPE_CASTER(volphoton::Affine, const_name("numpy.ndarray[float64, (4, 4)]"));
    bool load(handle src, bool convert) {
        if (!src || src.is_none()) return false;
        if (!convert && !isinstance<array>(src)) return false;
        auto a = array_t<double, array::c_style | array::forcecast>::ensure(src);
        if (!a) return false;
        if (a.ndim() != 2 || a.shape(1) != 4 || (a.shape(0) != 3 && a.shape(0) != 4)) return false;
        auto r = a.unchecked<2>();
        // A 4x4 must be affine in the column-vector convention: a Gf.Matrix4d (translation in the
        // last row) passed untransposed is refused rather than silently misread.
        if (a.shape(0) == 4 && (std::abs(r(3, 0)) > 1e-9 || std::abs(r(3, 1)) > 1e-9 || std::abs(r(3, 2)) > 1e-9 ||
                                std::abs(r(3, 3) - 1.0) > 1e-9))
            return false;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 4; ++j) value.m[i][j] = r(i, j);
        return true;
    }
    static handle cast(const volphoton::Affine& m, return_value_policy, handle) {
        array_t<double> a({4, 4});
        auto w = a.mutable_unchecked<2>();
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 4; ++j) w(i, j) = m.m[i][j];
        w(3, 0) = w(3, 1) = w(3, 2) = 0.0;
        w(3, 3) = 1.0;
        return a.release();
    }
};

}  // namespace detail
}  // namespace pybind11
