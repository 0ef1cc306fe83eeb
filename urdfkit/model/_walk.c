/* The one walk of urdfkit.model.index.Doc, over libxml2's nodes instead of lxml's proxies.
 *
 * check spends a fifth of its time in Doc's walk: for each of some 33,000 elements of
 * pybullet_data, lxml makes a proxy object, a tag string and a list of attribute pairs, and
 * the element rules build a memo key from them. Here the walk reads libxml2's tree through
 * lxml's public C API (lxml.etree_api.h): tags and attribute values come from the same
 * lxml functions its Python API calls (namespacedName, attributeValue, collectAttributes),
 * so every string is the one Python would see, but no proxy is made for an element unless it
 * is collected or a finding names it, and no attribute value is read unless the memo key
 * holds it. What it does, step for step, is Doc._walk and Doc._check in index.py (the
 * reference; tests/test_one_pass.py holds both to lxml's own walks and a plain oracle).
 *
 * Built with mypyc's modules by setup.py; where it is not built, or lxml's C API does not
 * match, index.py walks in (compiled) Python.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <stdint.h>
#include "lxml-version.h"
#include "etree_defs.h"
#include "lxml.etree.h"
#include "lxml.etree_api.h"

/* What one walk reads, fixed for its duration (borrowed references). */
typedef struct {
    struct LxmlDocument *doc;
    PyObject *buckets;       /* dict: tag -> list the walk appends such elements to */
    PyObject *findings;      /* list of (code, level, message, element) */
    PyObject *schema;        /* dict: tag -> (allowed attributes, allowed children) */
    PyObject *numeric;       /* dict: tag -> {attribute: how many numbers} */
    PyObject *opaque;        /* container of tags whose subtrees are not checked */
    long max_depth;
    PyObject *verdicts;      /* dict: memo key -> tuple of (code, level, message) */
    Py_ssize_t verdicts_max;
    PyObject *verdict;       /* callable (tag, items) -> tuple of (code, level, message) */
    PyObject *too_deep;      /* new reference, or NULL */
    int too_deep_set;
} Walk;

static PyObject *U801, *WARNING;
static PyTypeObject *element_type;  /* lxml.etree._Element */

/* Names as Python strings, made once: libxml2 keeps each element and attribute name once
 * in its dictionary, so a name's address repeats from element to element. A slot is
 * trusted only when its string still spells the name at that address (an address can be
 * reused for another name once a dictionary is freed), so a hit is always right; a miss
 * makes the string as lxml does. The strings keep their hash: dict lookups on them are
 * cheap. */
#define NAMES 1024  /* 2 ** (64 - 54) */
static struct { const xmlChar *at; PyObject *str; } names[NAMES];

static PyObject *name_of(const xmlChar *at) {
    /* Names sit side by side in libxml2's pools: mix every bit of the address. */
    size_t slot = (size_t)(((uint64_t)(uintptr_t)at * 0x9E3779B97F4A7C15ULL) >> 54);
    PyObject *str = names[slot].str;
    if (str != NULL && names[slot].at == at) {
        const char *utf8 = PyUnicode_AsUTF8(str);
        if (utf8 != NULL && strcmp(utf8, (const char *)at) == 0) {
            Py_INCREF(str);
            return str;
        }
        PyErr_Clear();
    }
    str = pyunicode(at);  /* lxml's own decoding of a name */
    if (str == NULL)
        return NULL;
    PyUnicode_InternInPlace(&str);
    Py_XSETREF(names[slot].str, Py_NewRef(str));
    names[slot].at = at;
    return str;
}

/* node.tag (lxml's "{href}name" in a namespace) or an attribute's name in items(). */
static PyObject *tag_of(xmlNode *node) {
    if (node->ns != NULL && node->ns->href != NULL)
        return namespacedName(node);
    return name_of(node->name);
}

/* An attribute's value as el.get gives it: the text of its one text child (what libxml2's
 * xmlGetNsProp copies), else lxml's own reading. */
static PyObject *value_of(xmlNode *node, xmlAttr *attr) {
    xmlNode *text = attr->children;
    if (text != NULL && text->next == NULL && text->type == XML_TEXT_NODE
            && text->content != NULL)
        return pyunicode(text->content);
    return attributeValue(node, attr);
}

/* The first element child of a node, as lxml's iteration filtered by isinstance(tag, str). */
static xmlNode *first_element(xmlNode *node) {
    for (xmlNode *c = node->children; c != NULL; c = c->next)
        if (c->type == XML_ELEMENT_NODE)
            return c;
    return NULL;
}

/* lxml's tag is "{href}name" for an element in a namespace, the plain name otherwise. */
static int is_namespaced(xmlNode *node) {
    return node->ns != NULL && node->ns->href != NULL;
}

/* A child element with a plain name (no namespace): lxml's tag equals `name` exactly then. */
static int named(xmlNode *c, const char *name) {
    return c->type == XML_ELEMENT_NODE && !is_namespaced(c)
           && strcmp((const char *)c->name, name) == 0;
}

static int add_finding(Walk *w, PyObject *code, PyObject *level, PyObject *message,
                       xmlNode *node) {
    PyObject *el = (PyObject *)elementFactory(w->doc, node);
    if (el == NULL)
        return -1;
    PyObject *row = PyTuple_Pack(4, code, level, message, el);
    Py_DECREF(el);
    if (row == NULL)
        return -1;
    int rc = PyList_Append(w->findings, row);
    Py_DECREF(row);
    return rc;
}

/* The memo key Doc._check makes, (tag, name, [value if it holds numbers], ...): a tuple
 * of the strings Python would see. */
static PyObject *tuple_key(xmlNode *node, xmlAttr *attr, PyObject *tag, PyObject *numeric) {
    PyObject *parts = PyList_New(1);
    if (parts == NULL)
        return NULL;
    Py_INCREF(tag);
    PyList_SET_ITEM(parts, 0, tag);
    for (; attr != NULL; attr = attr->next) {
        if (attr->type != XML_ATTRIBUTE_NODE)
            continue;
        PyObject *name = tag_of((xmlNode *)attr);
        if (name == NULL || PyList_Append(parts, name) < 0) {
            Py_XDECREF(name);
            Py_DECREF(parts);
            return NULL;
        }
        int holds_number = 0;
        if (numeric != NULL) {
            holds_number = PyDict_Contains(numeric, name);
            if (holds_number < 0) {
                Py_DECREF(name);
                Py_DECREF(parts);
                return NULL;
            }
        }
        Py_DECREF(name);
        if (holds_number) {
            PyObject *value = value_of(node, attr);
            if (value == NULL || PyList_Append(parts, value) < 0) {
                Py_XDECREF(value);
                Py_DECREF(parts);
                return NULL;
            }
            Py_DECREF(value);
        }
    }
    PyObject *key = PyList_AsTuple(parts);
    Py_DECREF(parts);
    return key;
}

/* The same key as bytes, for a plain element: no attribute in a namespace, at most
 * PLAIN_MAX attributes, every number-holding value one text node. The tag, the names and
 * those values, each ended by a NUL (which none can hold): whether a value follows a name
 * depends only on the tag and the name, so two keys are equal exactly when the tuples are.
 * No string is made for a value, and the key is one object. Sets *plain to 0, and returns
 * NULL without an error, for an element that is not plain. */
#define PLAIN_MAX 32
static PyObject *bytes_key(xmlAttr *attr, PyObject *tag, PyObject *numeric, int *plain) {
    const xmlChar *values[PLAIN_MAX];
    xmlAttr *attrs[PLAIN_MAX];
    int count = 0;
    *plain = 0;
    Py_ssize_t tag_len;
    const char *tag_utf8 = PyUnicode_AsUTF8AndSize(tag, &tag_len);
    if (tag_utf8 == NULL)
        return NULL;
    size_t size = (size_t)tag_len + 1;
    for (; attr != NULL; attr = attr->next) {
        if (attr->type != XML_ATTRIBUTE_NODE)
            continue;
        if (count == PLAIN_MAX || (attr->ns != NULL && attr->ns->href != NULL))
            return NULL;
        const xmlChar *value = NULL;
        if (numeric != NULL) {
            PyObject *name = name_of(attr->name);
            if (name == NULL)
                return NULL;
            int holds_number = PyDict_Contains(numeric, name);
            Py_DECREF(name);
            if (holds_number < 0)
                return NULL;
            if (holds_number) {
                xmlNode *text = attr->children;
                if (text == NULL || text->next != NULL || text->type != XML_TEXT_NODE
                        || text->content == NULL)
                    return NULL;
                value = text->content;
                size += strlen((const char *)value) + 1;
            }
        }
        size += strlen((const char *)attr->name) + 1;
        attrs[count] = attr;
        values[count] = value;
        count++;
    }
    PyObject *key = PyBytes_FromStringAndSize(NULL, (Py_ssize_t)size);
    if (key == NULL)
        return NULL;
    char *at = PyBytes_AS_STRING(key);
    memcpy(at, tag_utf8, (size_t)tag_len + 1);
    at += tag_len + 1;
    for (int i = 0; i < count; i++) {
        size_t n = strlen((const char *)attrs[i]->name) + 1;
        memcpy(at, attrs[i]->name, n);
        at += n;
        if (values[i] != NULL) {
            n = strlen((const char *)values[i]) + 1;
            memcpy(at, values[i], n);
            at += n;
        }
    }
    *plain = 1;
    return key;
}

/* Doc._check: U401-U402 and U801-U802 of one element's attributes, through the memo. */
static int check(Walk *w, xmlNode *node, PyObject *tag) {
    xmlAttr *attr = node->properties;
    while (attr != NULL && attr->type != XML_ATTRIBUTE_NODE)
        attr = attr->next;
    if (attr == NULL)
        return 0;  /* no attributes: nothing to say */
    PyObject *numeric = PyDict_GetItemWithError(w->numeric, tag);  /* borrowed */
    if (numeric == NULL) {
        if (PyErr_Occurred())
            return -1;
        int known = PyDict_Contains(w->schema, tag);
        if (known <= 0)
            return known;  /* an element no rule knows (or an error) */
    }
    int plain;
    PyObject *key = bytes_key(attr, tag, numeric, &plain);
    if (key == NULL) {
        if (plain || PyErr_Occurred())
            return -1;
        key = tuple_key(node, attr, tag, numeric);
        if (key == NULL)
            return -1;
    }
    PyObject *found = PyDict_GetItemWithError(w->verdicts, key);  /* borrowed */
    if (found != NULL) {
        Py_INCREF(found);
    } else {
        if (PyErr_Occurred()) {
            Py_DECREF(key);
            return -1;
        }
        PyObject *items = collectAttributes(node, 3);  /* el.items() */
        if (items == NULL) {
            Py_DECREF(key);
            return -1;
        }
        found = PyObject_CallFunctionObjArgs(w->verdict, tag, items, NULL);
        Py_DECREF(items);
        if (found == NULL || !PyTuple_Check(found)) {
            if (found != NULL)
                PyErr_SetString(PyExc_TypeError, "a verdict must be a tuple");
            Py_XDECREF(found);
            Py_DECREF(key);
            return -1;
        }
        if (PyDict_GET_SIZE(w->verdicts) >= w->verdicts_max)
            PyDict_Clear(w->verdicts);
        if (PyDict_SetItem(w->verdicts, key, found) < 0) {
            Py_DECREF(found);
            Py_DECREF(key);
            return -1;
        }
    }
    Py_DECREF(key);
    Py_ssize_t n = PyTuple_GET_SIZE(found);
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *f = PyTuple_GET_ITEM(found, i);
        if (!PyTuple_Check(f) || PyTuple_GET_SIZE(f) != 3) {
            PyErr_SetString(PyExc_TypeError, "a verdict holds (code, level, message) tuples");
            Py_DECREF(found);
            return -1;
        }
        if (add_finding(w, PyTuple_GET_ITEM(f, 0), PyTuple_GET_ITEM(f, 1),
                        PyTuple_GET_ITEM(f, 2), node) < 0) {
            Py_DECREF(found);
            return -1;
        }
    }
    Py_DECREF(found);
    return 0;
}

static int collect(Walk *w, xmlNode *node, PyObject *tag) {
    PyObject *bucket = PyDict_GetItemWithError(w->buckets, tag);  /* borrowed */
    if (bucket == NULL)
        return PyErr_Occurred() ? -1 : 0;
    PyObject *el = (PyObject *)elementFactory(w->doc, node);
    if (el == NULL)
        return -1;
    int rc = PyList_Append(bucket, el);
    Py_DECREF(el);
    return rc;
}

/* Doc._walk: visit node's subtree once; collect, and check elements when `checked`. */
static int walk(Walk *w, xmlNode *node, PyObject *tag, int checked, long depth) {
    PyObject *allowed = NULL;  /* borrowed */
    if (checked) {
        if (check(w, node, tag) < 0)
            return -1;
        PyObject *known = PyDict_GetItemWithError(w->schema, tag);
        if (known == NULL && PyErr_Occurred())
            return -1;
        if (known != NULL) {
            if (!PyTuple_Check(known) || PyTuple_GET_SIZE(known) != 2) {
                PyErr_SetString(PyExc_TypeError, "a schema entry is (attributes, children)");
                return -1;
            }
            allowed = PyTuple_GET_ITEM(known, 1);
        }
    }
    if (depth == w->max_depth && !w->too_deep_set) {
        xmlNode *deep = first_element(node);
        w->too_deep_set = deep != NULL;
        if (deep != NULL) {
            w->too_deep = (PyObject *)elementFactory(w->doc, deep);
            if (w->too_deep == NULL)
                return -1;
        }
    }
    int is_geometry = checked && PyUnicode_CompareWithASCIIString(tag, "geometry") == 0;
    xmlNode *shape = is_geometry ? first_element(node) : NULL;
    depth += 1;
    for (xmlNode *c = node->children; c != NULL; c = c->next) {
        if (c->type != XML_ELEMENT_NODE)
            continue;  /* comments, processing instructions, entities, text */
        PyObject *ctag = tag_of(c);
        if (ctag == NULL)
            return -1;
        int rc = collect(w, c, ctag);
        if (rc == 0) {
            if (!checked || is_namespaced(c)) {
                rc = c->children != NULL ? walk(w, c, ctag, 0, depth) : 0;
            } else {
                if (allowed != NULL) {
                    int ok = PySequence_Contains(allowed, ctag);
                    if (ok < 0) {
                        rc = -1;
                    } else if (!ok) {
                        PyObject *message = PyUnicode_FromFormat(
                            "<%U> is not known inside <%U>; PyBullet ignores it", ctag, tag);
                        rc = message == NULL ? -1 : add_finding(w, U801, WARNING, message, c);
                        Py_XDECREF(message);
                    }
                }
                if (rc == 0) {
                    int hidden = PySequence_Contains(w->opaque, ctag);
                    if (hidden < 0)
                        rc = -1;
                    else if (hidden || (shape != NULL && c != shape))
                        rc = c->children != NULL ? walk(w, c, ctag, 0, depth) : 0;
                    else if (c->children != NULL)
                        rc = walk(w, c, ctag, 1, depth);
                    else
                        rc = check(w, c, ctag);  /* a leaf: its attributes are all there is */
                }
            }
        }
        Py_DECREF(ctag);
        if (rc < 0)
            return -1;
    }
    return 0;
}

PyDoc_STRVAR(walk_doc,
"walk(root, tag, checked, buckets, findings, schema, numeric, opaque, max_depth,\n"
"     verdicts, verdicts_max, verdict)\n--\n\n"
"Doc._walk(root, tag, checked, 1) with Doc._check: append collected elements to\n"
"buckets[tag] and element findings to findings; return the first element nested deeper\n"
"than max_depth, or None.");

static PyObject *py_walk(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 12) {
        PyErr_SetString(PyExc_TypeError, "walk() takes 12 arguments");
        return NULL;
    }
    PyObject *root = args[0], *tag = args[1];
    if (!PyObject_TypeCheck(root, element_type) || !PyUnicode_Check(tag)
            || !PyDict_Check(args[3]) || !PyList_Check(args[4]) || !PyDict_Check(args[5])
            || !PyDict_Check(args[6]) || !PyDict_Check(args[9])) {
        PyErr_SetString(PyExc_TypeError, "walk(): an lxml element, a str tag, and the "
                        "buckets, findings, schema, numeric and verdicts as dict/list");
        return NULL;
    }
    int checked = PyObject_IsTrue(args[2]);
    long max_depth = PyLong_AsLong(args[8]);
    Py_ssize_t verdicts_max = PyLong_AsSsize_t(args[10]);
    if (checked < 0 || PyErr_Occurred())
        return NULL;
    struct LxmlElement *el = (struct LxmlElement *)root;
    if (el->_c_node == NULL) {
        PyErr_SetString(PyExc_ValueError, "walk(): an element without a node");
        return NULL;
    }
    Walk w = {el->_doc, args[3], args[4], args[5], args[6], args[7], max_depth, args[9],
              verdicts_max, args[11], NULL, 0};
    if (walk(&w, el->_c_node, tag, checked, 1) < 0) {
        Py_XDECREF(w.too_deep);
        return NULL;
    }
    if (w.too_deep == NULL)
        Py_RETURN_NONE;
    return w.too_deep;
}

PyDoc_STRVAR(first_doc,
"first(el, tag)\n--\n\n"
"next(el.iterchildren(tag), None) for a plain tag name (no namespace), without the iterator.");

static PyObject *py_first(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 2 || !PyUnicode_Check(args[1])) {
        PyErr_SetString(PyExc_TypeError, "first(el, tag): an element and a str tag");
        return NULL;
    }
    if (args[0] == Py_None)
        Py_RETURN_NONE;
    if (!PyObject_TypeCheck(args[0], element_type)) {
        PyErr_SetString(PyExc_TypeError, "first(el, tag): an lxml element");
        return NULL;
    }
    struct LxmlElement *el = (struct LxmlElement *)args[0];
    const char *tag = PyUnicode_AsUTF8(args[1]);
    if (tag == NULL)
        return NULL;
    if (el->_c_node == NULL)
        Py_RETURN_NONE;
    for (xmlNode *c = el->_c_node->children; c != NULL; c = c->next) {
        if (named(c, tag))
            return (PyObject *)elementFactory(el->_doc, c);
    }
    Py_RETURN_NONE;
}

/* An element's proxy, or None for no node. */
static PyObject *proxy(struct LxmlDocument *doc, xmlNode *node) {
    if (node == NULL)
        Py_RETURN_NONE;
    return (PyObject *)elementFactory(doc, node);
}

static struct LxmlElement *element_arg(PyObject *arg, const char *who) {
    if (!PyObject_TypeCheck(arg, element_type)) {
        PyErr_Format(PyExc_TypeError, "%s: an lxml element", who);
        return NULL;
    }
    struct LxmlElement *el = (struct LxmlElement *)arg;
    if (el->_c_node == NULL) {
        PyErr_Format(PyExc_ValueError, "%s: an element without a node", who);
        return NULL;
    }
    return el;
}

PyDoc_STRVAR(link_parts_doc,
"link_parts(link)\n--\n\n"
"LinkView's reading of a <link>'s children: (inertial, mass, inertia, parts, collisions),\n"
"the first <inertial>, its first <mass> and <inertia>, the <visual> and <collision>\n"
"children in order, and the <collision> ones.");

static PyObject *py_link_parts(PyObject *self, PyObject *arg) {
    struct LxmlElement *el = element_arg(arg, "link_parts()");
    if (el == NULL)
        return NULL;
    xmlNode *inertial = NULL, *mass = NULL, *inertia = NULL;
    PyObject *parts = PyList_New(0), *collisions = PyList_New(0);
    if (parts == NULL || collisions == NULL)
        goto fail;
    for (xmlNode *c = el->_c_node->children; c != NULL; c = c->next) {
        int collision = named(c, "collision");
        if (collision || named(c, "visual")) {
            PyObject *part = proxy(el->_doc, c);
            if (part == NULL || PyList_Append(parts, part) < 0
                    || (collision && PyList_Append(collisions, part) < 0)) {
                Py_XDECREF(part);
                goto fail;
            }
            Py_DECREF(part);
        } else if (inertial == NULL && named(c, "inertial")) {
            inertial = c;
            for (xmlNode *k = c->children; k != NULL; k = k->next) {
                if (mass == NULL && named(k, "mass"))
                    mass = k;
                else if (inertia == NULL && named(k, "inertia"))
                    inertia = k;
            }
        }
    }
    PyObject *a = proxy(el->_doc, inertial), *b = proxy(el->_doc, mass),
             *c = proxy(el->_doc, inertia);
    if (a == NULL || b == NULL || c == NULL) {
        Py_XDECREF(a);
        Py_XDECREF(b);
        Py_XDECREF(c);
        goto fail;
    }
    return Py_BuildValue("(NNNNN)", a, b, c, parts, collisions);
fail:
    Py_XDECREF(parts);
    Py_XDECREF(collisions);
    return NULL;
}

PyDoc_STRVAR(joint_parts_doc,
"joint_parts(joint)\n--\n\n"
"JointView's reading of a <joint>'s children: (parent, child, children, limit, axis,\n"
"origin, mimic), the first of each and every <child>.");

static PyObject *py_joint_parts(PyObject *self, PyObject *arg) {
    static const char *slots[] = {"parent", "limit", "axis", "origin", "mimic"};
    struct LxmlElement *el = element_arg(arg, "joint_parts()");
    if (el == NULL)
        return NULL;
    xmlNode *found[5] = {NULL, NULL, NULL, NULL, NULL};
    xmlNode *child = NULL;
    PyObject *children = PyList_New(0);
    if (children == NULL)
        return NULL;
    for (xmlNode *c = el->_c_node->children; c != NULL; c = c->next) {
        if (named(c, "child")) {
            PyObject *one = proxy(el->_doc, c);
            if (one == NULL || PyList_Append(children, one) < 0) {
                Py_XDECREF(one);
                Py_DECREF(children);
                return NULL;
            }
            Py_DECREF(one);
            if (child == NULL)
                child = c;
            continue;
        }
        for (int i = 0; i < 5; i++) {
            if (found[i] == NULL && named(c, slots[i])) {
                found[i] = c;
                break;
            }
        }
    }
    PyObject *out[6];
    xmlNode *nodes[6] = {found[0], child, found[1], found[2], found[3], found[4]};
    for (int i = 0; i < 6; i++) {
        out[i] = proxy(el->_doc, nodes[i]);
        if (out[i] == NULL) {
            for (int j = 0; j < i; j++)
                Py_DECREF(out[j]);
            Py_DECREF(children);
            return NULL;
        }
    }
    return Py_BuildValue("(NNNNNNN)", out[0], out[1], children, out[2], out[3], out[4],
                         out[5]);
}

PyDoc_STRVAR(collision_parts_doc,
"collision_parts(collision, shapes)\n--\n\n"
"(shape, origin) of a <collision>: the first child named in `shapes` of its <geometry>\n"
"children (in order), and its first <origin>; None for either when absent.");

static PyObject *py_collision_parts(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 2 || !PyTuple_Check(args[1])) {
        PyErr_SetString(PyExc_TypeError, "collision_parts(collision, shapes): a tuple of names");
        return NULL;
    }
    struct LxmlElement *el = element_arg(args[0], "collision_parts()");
    if (el == NULL)
        return NULL;
    xmlNode *shape = NULL, *origin = NULL;
    for (xmlNode *c = el->_c_node->children; c != NULL; c = c->next) {
        if (shape == NULL && named(c, "geometry")) {
            for (xmlNode *s = c->children; s != NULL && shape == NULL; s = s->next) {
                if (s->type != XML_ELEMENT_NODE || is_namespaced(s))
                    continue;
                PyObject *name = name_of(s->name);
                if (name == NULL)
                    return NULL;
                int known = PySequence_Contains(args[1], name);
                Py_DECREF(name);
                if (known < 0)
                    return NULL;
                if (known)
                    shape = s;
            }
        } else if (origin == NULL && named(c, "origin")) {
            origin = c;
        }
    }
    PyObject *a = proxy(el->_doc, shape), *b = a == NULL ? NULL : proxy(el->_doc, origin);
    if (b == NULL) {
        Py_XDECREF(a);
        return NULL;
    }
    return Py_BuildValue("(NN)", a, b);
}

static PyMethodDef methods[] = {
    {"walk", (PyCFunction)(void (*)(void))py_walk, METH_FASTCALL, walk_doc},
    {"first", (PyCFunction)(void (*)(void))py_first, METH_FASTCALL, first_doc},
    {"link_parts", (PyCFunction)py_link_parts, METH_O, link_parts_doc},
    {"joint_parts", (PyCFunction)py_joint_parts, METH_O, joint_parts_doc},
    {"collision_parts", (PyCFunction)(void (*)(void))py_collision_parts, METH_FASTCALL,
     collision_parts_doc},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "urdfkit.model._walk",
    "Doc's one walk over libxml2's nodes (see index.py).", -1, methods,
};

PyMODINIT_FUNC PyInit__walk(void) {
    /* Fails (ImportError) when this lxml's C API is not the one built against: the
       capsules carry their signatures. index.py then walks in Python. */
    if (import_lxml__etree() < 0)
        return NULL;
    /* The element struct read here (its document and node) is lxml's public one; a new
       major version may move it: then the Python walk, not a guess. */
    PyObject *etree = PyImport_ImportModule("lxml.etree");
    PyObject *running = etree == NULL ? NULL : PyObject_GetAttrString(etree, "__version__");
    element_type = etree == NULL ? NULL
                   : (PyTypeObject *)PyObject_GetAttrString(etree, "_Element");
    Py_XDECREF(etree);
    if (element_type == NULL || !PyType_Check(element_type)) {
        Py_XDECREF(running);
        PyErr_SetString(PyExc_ImportError, "lxml.etree has no _Element type");
        return NULL;
    }
    if (running == NULL)
        return NULL;
    const char *text = PyUnicode_Check(running) ? PyUnicode_AsUTF8(running) : NULL;
    int same = text != NULL && atoi(text) == atoi(LXML_VERSION_STRING);
    Py_DECREF(running);
    if (!same) {
        PyErr_Format(PyExc_ImportError, "urdfkit.model._walk was built for lxml %s",
                     LXML_VERSION_STRING);
        return NULL;
    }
    U801 = PyUnicode_InternFromString("U801");
    WARNING = PyUnicode_InternFromString("warning");
    if (U801 == NULL || WARNING == NULL)
        return NULL;
    PyObject *m = PyModule_Create(&module);
    if (m == NULL)
        return NULL;
    if (PyModule_AddStringConstant(m, "LXML_VERSION", LXML_VERSION_STRING) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
