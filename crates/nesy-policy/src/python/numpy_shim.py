# A small, vetted subset of numpy for policies ("import numpy as np"). Pure Python over
# lists: 1-D and 2-D float arrays with element-wise arithmetic and the handful of
# functions robot policies use. It runs with the policy's curated builtins.
import math

pi = math.pi
e = math.e
inf = math.inf
float64 = float
int64 = int


def _flatten(data):
    if isinstance(data, ndarray):
        return list(data._data), data._shape
    if isinstance(data, (list, tuple)):
        if data and isinstance(data[0], (list, tuple, ndarray)):
            rows = [_flatten(row) for row in data]
            width = rows[0][1]
            flat = []
            for values, shape in rows:
                if shape != width:
                    raise ValueError("np.array: rows of different lengths")
                flat.extend(values)
            return flat, (len(rows),) + width
        return [_scalar(x) for x in data], (len(data),)
    return [_scalar(data)], ()


def _scalar(x):
    if isinstance(x, bool):
        return x
    if isinstance(x, (int, float)):
        return x
    raise TypeError(f"np.array: expected numbers, got {x.__class__.__name__}")


class ndarray:
    """An n-dimensional (n <= 2) array of numbers."""

    def __init__(self, data, shape):
        self._data = data
        self._shape = shape

    @property
    def shape(self):
        return self._shape

    @property
    def ndim(self):
        return len(self._shape)

    @property
    def size(self):
        return len(self._data)

    @property
    def T(self):
        if self.ndim < 2:
            return self.copy()
        rows, cols = self._shape
        return ndarray([self._data[r * cols + c] for c in range(cols) for r in range(rows)], (cols, rows))

    def __len__(self):
        if not self._shape:
            raise TypeError("len() of unsized object")
        return self._shape[0]

    def _row(self, i):
        cols = self._shape[1]
        return ndarray(self._data[i * cols:(i + 1) * cols], (cols,))

    def __getitem__(self, key):
        if isinstance(key, tuple):
            if len(key) == 1:
                return self[key[0]]
            if len(key) != 2 or self.ndim != 2:
                raise IndexError("too many indices for array")
            first, second = key
            if isinstance(first, int):
                return self._row(_index(first, self._shape[0]))[second]
            rows = self[first]
            return array([row[second] for row in rows])
        if isinstance(key, slice):
            if self.ndim == 1:
                return ndarray(self._data[key], (len(range(*key.indices(self._shape[0]))),))
            return array([self._row(i).tolist() for i in range(*key.indices(self._shape[0]))])
        if isinstance(key, int):
            i = _index(key, self._shape[0])
            return self._data[i] if self.ndim == 1 else self._row(i)
        raise IndexError("only integers and slices are valid indices")

    def __setitem__(self, key, value):
        if isinstance(key, int) and self.ndim == 1:
            self._data[_index(key, self._shape[0])] = _scalar(value)
        elif isinstance(key, int) and self.ndim == 2:
            values, _shape = _flatten(value)
            cols = self._shape[1]
            i = _index(key, self._shape[0])
            if len(values) == 1:
                values = values * cols
            if len(values) != cols:
                raise ValueError("could not broadcast row")
            self._data[i * cols:(i + 1) * cols] = values
        elif isinstance(key, tuple) and len(key) == 2 and self.ndim == 2:
            i = _index(key[0], self._shape[0])
            j = _index(key[1], self._shape[1])
            self._data[i * self._shape[1] + j] = _scalar(value)
        else:
            raise IndexError("unsupported assignment index")

    def __iter__(self):
        if self.ndim == 1:
            return iter(list(self._data))
        return iter([self._row(i) for i in range(self._shape[0])])

    def _binary(self, other, op):
        if isinstance(other, (int, float)):
            return ndarray([op(a, other) for a in self._data], self._shape)
        values, shape = _flatten(other)
        if shape == self._shape:
            return ndarray([op(a, b) for a, b in zip(self._data, values)], self._shape)
        if shape == ():
            return ndarray([op(a, values[0]) for a in self._data], self._shape)
        if self.ndim == 2 and shape == (self._shape[1],):
            cols = self._shape[1]
            return ndarray([op(a, values[i % cols]) for i, a in enumerate(self._data)], self._shape)
        raise ValueError(f"operands could not be broadcast together with shapes {self._shape} {shape}")

    def _reflected(self, other, op):
        return self._binary(other, lambda a, b: op(b, a))

    def __add__(self, other):
        return self._binary(other, lambda a, b: a + b)

    def __radd__(self, other):
        return self._reflected(other, lambda a, b: a + b)

    def __sub__(self, other):
        return self._binary(other, lambda a, b: a - b)

    def __rsub__(self, other):
        return self._reflected(other, lambda a, b: a - b)

    def __mul__(self, other):
        return self._binary(other, lambda a, b: a * b)

    def __rmul__(self, other):
        return self._reflected(other, lambda a, b: a * b)

    def __truediv__(self, other):
        return self._binary(other, lambda a, b: a / b)

    def __rtruediv__(self, other):
        return self._reflected(other, lambda a, b: a / b)

    def __floordiv__(self, other):
        return self._binary(other, lambda a, b: a // b)

    def __pow__(self, other):
        return self._binary(other, _bounded_pow)

    def __neg__(self):
        return ndarray([-a for a in self._data], self._shape)

    def __pos__(self):
        return self.copy()

    def __abs__(self):
        return ndarray([abs(a) for a in self._data], self._shape)

    def __eq__(self, other):
        return self._binary(other, lambda a, b: a == b)

    def __ne__(self, other):
        return self._binary(other, lambda a, b: a != b)

    def __lt__(self, other):
        return self._binary(other, lambda a, b: a < b)

    def __le__(self, other):
        return self._binary(other, lambda a, b: a <= b)

    def __gt__(self, other):
        return self._binary(other, lambda a, b: a > b)

    def __ge__(self, other):
        return self._binary(other, lambda a, b: a >= b)

    def __bool__(self):
        if len(self._data) != 1:
            raise ValueError("The truth value of an array with more than one element is ambiguous. Use a.any() or a.all()")
        return bool(self._data[0])

    def __repr__(self):
        return f"array({self.tolist()!r})"

    __hash__ = None

    def tolist(self):
        if self.ndim == 2:
            return [self._row(i).tolist() for i in range(self._shape[0])]
        if self.ndim == 0:
            return self._data[0]
        return list(self._data)

    def copy(self):
        return ndarray(list(self._data), self._shape)

    def astype(self, kind):
        return ndarray([kind(a) for a in self._data], self._shape)

    def sum(self, axis=None):
        return sum(self, axis)

    def mean(self, axis=None):
        return mean(self, axis)

    def min(self, axis=None):
        return amin(self, axis)

    def max(self, axis=None):
        return amax(self, axis)

    def any(self):
        return any(self._data)

    def all(self):
        return all(self._data)

    def flatten(self):
        return ndarray(list(self._data), (len(self._data),))

    def reshape(self, *shape):
        if len(shape) == 1 and isinstance(shape[0], tuple):
            shape = shape[0]
        if math.prod(shape) != len(self._data) or len(shape) > 2:
            raise ValueError(f"cannot reshape array of size {len(self._data)} into shape {shape}")
        return ndarray(list(self._data), tuple(shape))


def _bounded_pow(a, b):
    if isinstance(a, int) and isinstance(b, int) and abs(b) > 64:
        raise ValueError("np power: integer exponent too large")
    return a ** b


def _index(i, n):
    if i < 0:
        i += n
    if not 0 <= i < n:
        raise IndexError(f"index {i} is out of bounds for axis 0 with size {n}")
    return i


def array(data, dtype=None):
    values, shape = _flatten(data)
    if len(shape) > 2:
        raise ValueError("np subset: arrays have at most 2 dimensions")
    result = ndarray(values, shape)
    return result.astype(dtype) if dtype is not None else result


asarray = array


def zeros(shape):
    shape = (shape,) if isinstance(shape, int) else tuple(shape)
    return ndarray([0.0] * math.prod(shape), shape)


def ones(shape):
    shape = (shape,) if isinstance(shape, int) else tuple(shape)
    return ndarray([1.0] * math.prod(shape), shape)


def zeros_like(a):
    return zeros(asarray(a).shape)


def linspace(start, stop, num=50):
    if num < 2:
        return array([float(start)][:num])
    step = (stop - start) / (num - 1)
    return array([start + i * step for i in range(num)])


def arange(start, stop=None, step=1):
    if stop is None:
        start, stop = 0, start
    count = max(0, math.ceil((stop - start) / step))
    return array([start + i * step for i in range(count)])


def _map(x, f):
    if isinstance(x, (int, float)):
        return f(x)
    a = asarray(x)
    return ndarray([f(v) for v in a._data], a._shape)


def sqrt(x):
    return _map(x, math.sqrt)


def sin(x):
    return _map(x, math.sin)


def cos(x):
    return _map(x, math.cos)


def tan(x):
    return _map(x, math.tan)


def arctan(x):
    return _map(x, math.atan)


def arcsin(x):
    return _map(x, math.asin)


def arccos(x):
    return _map(x, math.acos)


def radians(x):
    return _map(x, math.radians)


def degrees(x):
    return _map(x, math.degrees)


deg2rad = radians
rad2deg = degrees


def abs(x):
    return _map(x, lambda v: v if v >= 0 else -v)


absolute = abs


def floor(x):
    return _map(x, math.floor)


def ceil(x):
    return _map(x, math.ceil)


def round(x, decimals=0):
    return _map(x, lambda v: _round(v, decimals))


def _round(v, decimals):
    factor = 10 ** decimals
    return math.floor(v * factor + 0.5) / factor


around = round


def arctan2(y, x):
    if isinstance(y, (int, float)) and isinstance(x, (int, float)):
        return math.atan2(y, x)
    return asarray(y)._binary(x, math.atan2)


def hypot(a, b):
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return math.hypot(a, b)
    return asarray(a)._binary(b, math.hypot)


def clip(x, low, high):
    return _map(x, lambda v: low if v < low else high if v > high else v)


def _reduce(a, axis, f):
    a = asarray(a)
    if axis is None or a.ndim == 1:
        if axis not in (None, 0, -1):
            raise ValueError("axis out of range")
        return f(a._data)
    rows, cols = a._shape
    if axis in (0, -2):
        return array([f([a._data[r * cols + c] for r in range(rows)]) for c in range(cols)])
    if axis in (1, -1):
        return array([f(a._data[r * cols:(r + 1) * cols]) for r in range(rows)])
    raise ValueError("axis out of range")


def sum(a, axis=None):
    return _reduce(a, axis, math.fsum)


def mean(a, axis=None):
    return _reduce(a, axis, lambda v: math.fsum(v) / len(v))


def amin(a, axis=None):
    return _reduce(a, axis, min)


def amax(a, axis=None):
    return _reduce(a, axis, max)


def argmin(a):
    data = asarray(a)._data
    return data.index(min(data))


def argmax(a):
    data = asarray(a)._data
    return data.index(max(data))


def minimum(a, b):
    return asarray(a)._binary(b, lambda x, y: x if x < y else y)


def maximum(a, b):
    return asarray(a)._binary(b, lambda x, y: x if x > y else y)


def dot(a, b):
    a = asarray(a)
    b = asarray(b)
    if a.ndim != 1 or b.ndim != 1 or a.shape != b.shape:
        raise ValueError("np subset: dot supports two vectors of equal length")
    return math.fsum(x * y for x, y in zip(a._data, b._data))


def cross(a, b):
    a = asarray(a)._data
    b = asarray(b)._data
    if len(a) != 3 or len(b) != 3:
        raise ValueError("np subset: cross supports 3-vectors")
    return array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def concatenate(arrays):
    values = []
    for a in arrays:
        a = asarray(a)
        if a.ndim != 1:
            raise ValueError("np subset: concatenate supports vectors")
        values.extend(a._data)
    return array(values)


def isclose(a, b, rtol=1e-05, atol=1e-08):
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return abs(a - b) <= atol + rtol * abs(b)
    return asarray(a)._binary(b, lambda x, y: (x - y if x >= y else y - x) <= atol + rtol * (y if y >= 0 else -y))


def allclose(a, b, rtol=1e-05, atol=1e-08):
    result = isclose(a, b, rtol, atol)
    return result if isinstance(result, bool) else result.all()


def copy(a):
    return asarray(a).copy()


class _Linalg:
    @staticmethod
    def norm(x):
        return math.sqrt(math.fsum(v * v for v in asarray(x)._data))


linalg = _Linalg()
